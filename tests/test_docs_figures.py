"""
Figures that cannot drift (issue 19): every figure README.md and docs/*.md
quote from a benchmark through a ``<!-- figure: record:path format -->``
marker (:mod:`benchmarks.docs_figures`) is the benchmark's recorded one in
``benchmarks/results/``; the README's figures of the editor's drag refit and
the REST fit, once stale, are marked.
"""

from __future__ import annotations

import json

import pytest

from benchmarks import docs_figures
from benchmarks.docs_figures import figures, pages, recorded, rewrite, stale


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(docs_figures.ROOT)))
def test_every_marked_figure_is_the_recorded_one(page):
    wrong = stale(page.read_text(encoding="utf-8"))
    assert not wrong, "\n".join(
        f"{page.name}:{w['line']}: {w['key']} quotes {w['quoted']}, recorded {w.get('recorded', w.get('error'))}"
        for w in wrong)


def test_the_readme_quotes_the_editor_and_rest_figures_from_their_records():
    keys = {f["key"] for f in figures((docs_figures.ROOT / "README.md").read_text(encoding="utf-8"))}
    assert {"editor_speed:drag_to_frame_ms.gentle.median_ms", "editor_speed:drag_to_frame_ms.gentle.p90_ms",
            "service_load:rest_fit_unseen_ms.p50"} <= keys


def test_every_record_says_how_it_was_made():
    for record in sorted(docs_figures.RESULTS.glob("*.json")):
        view = json.loads(record.read_text())
        assert {"command", "date"} <= set(view), record.name
        loads = view.get("load_average") or [row.get("load_average") for row in view.get("rows", [])]
        assert loads, f"{record.name} records no load average"


def test_a_stale_figure_is_caught_and_rewritten():
    value = recorded("editor_speed", "drag_to_curve_ms.gentle.median_ms")
    good = f"drag <!-- figure: editor_speed:drag_to_curve_ms.gentle.median_ms .0f -->**{value:.0f}** ms"
    assert not stale(good)
    bad = good.replace(f"**{value:.0f}**", "**1,024**")
    (item,) = stale(bad)
    assert item["quoted"] == "1,024" and item["recorded"] == f"{value:.0f}"
    assert rewrite(bad) == good
    assert stale("<!-- figure: editor_speed:no.such.key .0f -->3")[0]["error"].endswith("(at 'no')")
    assert stale("<!-- figure: no_such_benchmark:x .0f -->3")[0]["error"].startswith("no record")
