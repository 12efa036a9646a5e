"""
What one editor page costs the browser tests' machine
=====================================================

The browser tests open the editor in a fresh browser context (a window of
its own) for each page. This loads the editor that way, ``--rounds`` times
(default 8, after one load of each not counted) in each of two Chromiums
launched side by side, in turns (the order swapped every round):

-   ``plain``: the tests' switches (tests/static/editor_pages.py's
    ``CHROMIUM_ARGS``) alone;
-   ``tests``: what the tests launch (``editor_pages.launch``), which also
    disables ``UNUSED_FEATURES``: the address bar's popup, a WebUI page
    that Chromium loads in a renderer of its own for every new window.

A load is a new context and page, the editor opened and settled (its first
fit drawn), as ``open_editor`` and ``settled`` do. Its CPU seconds are read
from ``/proc`` before the context closes, by kind of process
(:data:`KINDS`, benchmarks/suite_cpu.py's classes; both Chromiums' processes
are read): Chromium's renderers, browser process, GPU process (SwiftShader)
and the rest of Chromium, playwright's Node.js driver, and the server with
its fork server and workers. Prints a table and records benchmarks/results/browser_page_cost.json
(``figures.<side>.cpu_s`` and ``.renderer_cpu_s``: median and max a load;
``saved_cpu_s_median``: plain's median less the tests')::

    .venv/bin/python benchmarks/browser_page_cost.py [--rounds N]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "static"))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.server_start import processes  # noqa: E402
from benchmarks.suite_cpu import classify  # noqa: E402
from benchmarks.suite_time import TICK  # noqa: E402
from conftest import server_process  # noqa: E402
from editor_pages import launch, open_editor, settled  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402

SIDES = ("plain", "tests")
KINDS = ("chromium_renderer", "chromium_gpu", "chromium_other", "chromium_browser", "playwright", "server")
"""The kinds of process a load is read by: benchmarks/suite_cpu.py's classes, and the server's session."""


def cpu_by_process(servers: set[int]) -> dict[int, tuple[str, float]]:
    """
    Each process of a kind in :data:`KINDS`: (kind, its CPU seconds so far);
    the server with its fork server and workers by their session, the rest
    by :func:`benchmarks.suite_cpu.classify`.
    """
    seen: dict[int, tuple[str, float]] = {}
    for pid, fields, command in processes():
        kind = "server" if int(fields[3]) in servers else classify(command)
        if kind in KINDS:
            seen[pid] = (kind, (int(fields[11]) + int(fields[12])) / TICK)
    return seen


def load_once(browser, url: str, servers: set[int]) -> tuple[float, Counter]:
    """One editor load in a fresh context: its wall seconds and CPU seconds by kind."""
    before = cpu_by_process(servers)
    start = time.perf_counter()
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    try:
        page = context.new_page()
        open_editor(page, url)
        settled(page)
        wall = time.perf_counter() - start
        after = cpu_by_process(servers)
    finally:
        context.close()
    spent: Counter = Counter()
    for pid, (kind, seconds) in after.items():
        spent[kind] += seconds - before.get(pid, (kind, 0.0))[1]
    return wall, spent


def _summary(values: list[float]) -> dict[str, float]:
    return {"median": round(statistics.median(values), 3), "max": round(max(values), 3)}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=8, help="loads counted on each side (default 8)")
    args = parser.parse_args(argv)
    if not 1 <= args.rounds <= 100:
        parser.error(f"--rounds must lie in [1, 100], got {args.rounds}")
    load = load_average()
    runs: dict[str, list[dict]] = {side: [] for side in SIDES}
    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data") as server, sync_playwright() as p:
        browsers = {
            "plain": launch(p, plain=True),
            "tests": launch(p),
        }
        servers = {server.process.pid}
        url = server.url + "/"
        try:
            for side in SIDES:  # not counted: the server's first fits, the browsers' caches
                load_once(browsers[side], url, servers)
            for round_ in range(args.rounds):
                for side in SIDES if round_ % 2 == 0 else SIDES[::-1]:
                    wall, spent = load_once(browsers[side], url, servers)
                    runs[side].append(
                        {
                            "wall_s": round(wall, 3),
                            "cpu_s": round(sum(spent.values()), 3),
                            "kinds": {k: round(v, 3) for k, v in sorted(spent.items())},
                        }
                    )
        finally:
            for browser in browsers.values():
                browser.close()
    figures = {}
    print(f"{'side':<6} {'CPU s a load, median (max)':>28} {'renderer':>9} {'browser':>8} {'GPU':>6} {'wall s':>7}")
    for side in SIDES:
        rows = runs[side]
        kind_median = {kind: round(statistics.median(r["kinds"].get(kind, 0.0) for r in rows), 3) for kind in KINDS}
        figures[side] = {
            "cpu_s": _summary([r["cpu_s"] for r in rows]),
            "renderer_cpu_s": _summary([r["kinds"].get("chromium_renderer", 0.0) for r in rows]),
            "wall_s": _summary([r["wall_s"] for r in rows]),
            "cpu_s_median_by_kind": kind_median,
        }
        f = figures[side]
        print(
            f"{side:<6} {f['cpu_s']['median']:>19.2f} ({f['cpu_s']['max']:.2f}) "
            f"{kind_median['chromium_renderer']:>9.2f} {kind_median['chromium_browser']:>8.2f} "
            f"{kind_median['chromium_gpu']:>6.2f} {f['wall_s']['median']:>7.2f}"
        )
    figures["saved_cpu_s_median"] = round(figures["plain"]["cpu_s"]["median"] - figures["tests"]["cpu_s"]["median"], 3)
    print(f"saved a load (median): {figures['saved_cpu_s_median']:.2f} CPU s")
    path = write_result("browser_page_cost", figures, load, rounds=args.rounds, runs=runs)
    print(f"recorded {path.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
