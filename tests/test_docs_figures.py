"""
Figures that cannot drift: every figure README.md and docs/*.md quote from
a benchmark through a ``<!-- figure: record:path format -->`` marker
(:mod:`benchmarks.docs_figures`) is the benchmark's recorded one in
``benchmarks/results/``; the README's figures of the editor's drag refit and
the REST fit are marked; every number of the figure column of the rows of
docs/results.md's "Headline figures, in full" read from a record carries its
marker (:data:`RECORDED_ROWS`), so a row cannot quietly lose one, and so
does every number of the README's "Headline figures", a short table (at
most 10 rows, no cell over 200 characters) whose rows link to docs/results.md.
"""

from __future__ import annotations

import json
import re

import pytest

from benchmarks import docs_figures
from benchmarks.docs_figures import MARKER, figures, pages, recorded, rewrite, stale

RECORDED_ROWS = (
    "accuracy, 22 conductors",
    "Al / Au / Cu",
    "float16 against float32",
    "the worst point",
    "rgb-conductor kind",
    "fit time, n, k to float16 pack",
    "fit time with the max guard",
    "service: fits/s with metrics",
    "service on PostgreSQL",
    "`/healthz` and pack download p99",
    "REST fit of unseen data",
    "preview with the spectral reference",
    "exports at eta_i 1.5",
    "shader cost at 2560 x 1440",
    "mean FLIP vs spectral reference",
    "split sum vs Monte Carlo",
    "three.js through",
    "refit from edited curves",
    "refractiveindex.info `main` shelf",
    "exports seen from air in the tool",
    "exports in an ACEScg host",
    "a metal from F0 and F82",
    "repeated export download",
    "hard curve edits",
    "scene packs: the shipped material",
    "extreme but finite n, k",
    "gapped data (100 nm gaps)",
    "`python -m fitting fit Au`",
    "the three.js package",
)
"""The rows of docs/results.md's "Headline figures, in full" whose figures
are all read from a record (by the start of their first cell): every number
of their figure column has its marker."""

README_ROWS_MAX = 10
README_CELL_MAX = 200
README_LINES_MAX = 250

NUMBER = re.compile(r"(?<![\w.])-?[0-9]+(?:,[0-9]{3})*(?:\.[0-9]+)?")
TARGET = re.compile(r"target (?:p50 )?[0-9.]+(?: / [0-9.]+)?")
"""A target the figure is held to is a requirement, not a measured number."""


def _rows(page: str, heading: str) -> list[list[str]]:
    """The cells of each row (not the header or rule) of the first table under ``heading`` of ``page``."""
    section = page.split(f"## {heading}\n", 1)[1].split("\n## ", 1)[0]
    rows = []
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
        if line.startswith("|") and len(cells) >= 3 and not set(cells[0]) <= {"-"}:
            rows.append(cells)
    return rows[1:]


def _measures_table(page: str) -> dict[str, str]:
    """The first cell of each row of docs/results.md's "Headline figures, in full" and its figure cell."""
    return {cells[0]: cells[1] for cells in _rows(page, "Headline figures, in full")}


def unmarked_numbers(cell: str) -> list[str]:
    """The numbers of ``cell`` that no figure marker precedes (targets aside)."""
    bare = MARKER.sub("", cell)
    bare = TARGET.sub("", bare)
    bare = re.sub(r"<!--.*?-->", "", bare)
    return NUMBER.findall(bare)


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(docs_figures.ROOT)))
def test_every_marked_figure_is_the_recorded_one(page):
    wrong = stale(page.read_text(encoding="utf-8"))
    assert not wrong, "\n".join(
        f"{page.name}:{w['line']}: {w['key']} quotes {w['quoted']}, recorded {w.get('recorded', w.get('error'))}"
        for w in wrong
    )


def test_the_readme_quotes_the_editor_and_rest_figures_from_their_records():
    keys = {f["key"] for f in figures((docs_figures.ROOT / "README.md").read_text(encoding="utf-8"))}
    assert {
        "editor_live_latency:busy.all.move_to_frame_ms.median_ms",
        "editor_live_latency:busy.all.move_to_frame_ms.p99_ms",
        "service_load:rest_fit_unseen_ms.p50",
    } <= keys


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


@pytest.mark.parametrize("row", RECORDED_ROWS)
def test_every_figure_of_a_recorded_row_is_marked(row):
    table = _measures_table((docs_figures.ROOT / "docs" / "results.md").read_text(encoding="utf-8"))
    (cell,) = [figure for what, figure in table.items() if what.startswith(row)]
    assert MARKER.search(cell), f"results.md row {row!r} quotes no recorded figure"
    assert not unmarked_numbers(cell), f"results.md row {row!r} quotes unmarked numbers {unmarked_numbers(cell)}"


def test_the_readme_headline_figures_are_short_marked_and_linked():
    readme = (docs_figures.ROOT / "README.md").read_text(encoding="utf-8")
    rows = _rows(readme, "Headline figures")
    assert 1 <= len(rows) <= README_ROWS_MAX, len(rows)
    for what, figure, record in rows:
        assert MARKER.search(figure) and not unmarked_numbers(figure), (what, unmarked_numbers(figure))
        assert "](docs/results.md#" in record, what
    assert len(readme.splitlines()) < README_LINES_MAX
    long = [
        cell[:60]
        for line in readme.splitlines()
        if line.startswith("|")
        for cell in line.strip().strip("|").split(" | ")
        if len(cell.strip()) > README_CELL_MAX
    ]
    assert not long, long


def test_an_unmarked_number_in_a_row_is_caught():
    marked = "<!-- figure: editor_speed:drag_to_curve_ms.gentle.median_ms .0f -->**41** ms (target 50 ms)"
    assert unmarked_numbers(marked) == []
    assert unmarked_numbers(marked + ", p90 91 ms") == ["91"]
    assert unmarked_numbers("0.011-0.035") == ["0.011", "0.035"]
