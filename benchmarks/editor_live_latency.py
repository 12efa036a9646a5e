"""
Live drag latency of the editor, idle and with the cores kept busy
=================================================================

Debian's Chromium (headless, software WebGL2 through SwiftShader) drives the
editor served by a real ``python -m service`` process on 127.0.0.1. Each
drag holds a control point and moves it (``--moves`` pointer moves, one every
40 ms): gentle drags (a channel at 50 degrees, a few px per move) and
extreme ones (green at 60 degrees pulled down 10-14 px a move, an edit the
model cannot follow); after each the edit is undone, so drags do not pile
up, and each drag of each phase ends on a curve of its own, so that no full
refit is served from the store. Measured, from the pointer events' own time stamps (``event.timeStamp``,
caught before the page's handlers) and the page's frames
(``window.cfTelemetry``):

-   ``move_to_frame_ms``: for every pointer move, the time to the first
    preview frame that shows its refit (of that move or a later one);
    median, p90, p99 and worst, gentle and extreme;
-   ``release_to_final_ms``: from the pointer's release (the drag's own
    ``pointerup``) to the first frame of the server's full refit; and where
    that wait goes (``release``): the release to the request sent (a request
    in flight first), the request to its answer, of it the server's own fit
    (the answer's ``timings.total``) and the rest (a worker's queue, the
    store, the curves, the round trip), the answer to its frame;
-   where a live refit's time goes, each step on the page's clock: the
    move's event to its edit (the page's handler), the edit to its message
    posted, the message to the worker's start (the wait for a solve in
    flight), ``solve_ms`` (the worker's solve), its end to the answer
    handled on the page (the message back, the main thread's queue), and
    the answer to the frame drawn (the wait for the next animation frame,
    the curve and the WebGL ball at half resolution);
-   the same drags twice, in one run: ``idle`` (no load added) and
    ``busy``: ``--busy`` busy-loop processes (two a core by default),
    each pinned to one core, started after the idle phase; the busy phase
    begins once the 1-minute load average reaches ``--busy-load`` (4 by
    default; at most 5 minutes' wait, the load reached is recorded);
-   the figures over all drags of a phase (gentle and extreme together:
    the target's median and p99), and the ratio busy / idle of the medians.

The load average at the start and end of each phase is recorded beside the
figures: on a shared machine "idle" means no load added by this run.

Run: ``.venv/bin/python benchmarks/editor_live_latency.py [--drags 20] [--moves 20] [--busy 4] [--busy-load 4]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from conftest import server_process  # noqa: E402

from benchmarks.editor_speed import ARGS, READY, percentile  # noqa: E402  (the same page, flags and statistic)
from benchmarks.record import load_average, write_result  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402

SETTLED = (
    "() => { const id = document.getElementById('fit-id').textContent;"
    " return !document.body.hasAttribute('aria-busy') && document.getElementById('preview-state').hidden"
    " && document.getElementById('preview').dataset.fit === id; }"
)
# The pointer events' time stamps, caught before the page's own handlers (capture phase): each move's
# first event (pointerrawupdate where Chromium has it, as the page follows it; else pointermove).
LISTEN = """() => {
  window.cfMoves = []; window.cfReleases = [];
  const move = "onpointerrawupdate" in window ? "pointerrawupdate" : "pointermove";
  document.addEventListener(move, (e) => { if (e.buttons) window.cfMoves.push(e.timeStamp); }, true);
  document.addEventListener("pointerup", (e) => window.cfReleases.push(e.timeStamp), true);
}"""


def summary(values):
    if not values:
        return {"n": 0}
    return {
        "median_ms": statistics.median(values),
        "p90_ms": percentile(values, 0.9),
        "p99_ms": percentile(values, 0.99),
        "worst_ms": max(values),
        "n": len(values),
    }


def editor(browser, url):
    """A page on the editor, ready, after one edit undone (an artist's first touch warms the service's worker)."""
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    page.goto(url)
    page.wait_for_function(READY, timeout=120_000)
    page.locator("input[name=channel][value='1']").check()
    page.locator("circle.handle.c1[data-angle='20']").focus()
    page.keyboard.press("ArrowUp")
    page.wait_for_function(SETTLED, timeout=120_000)
    page.click("#undo")
    page.wait_for_function(SETTLED, timeout=120_000)
    page.evaluate(LISTEN)
    return page


def drag(page, d, moves, extreme, phase_index=0):
    """
    One drag: (move -> frame latencies (ms), moves never shown live, release -> final frame (ms),
    the live refits' steps, the release's steps).
    """
    channel, angle = (1, 60) if extreme else (d % 3, 50)
    page.locator(f"input[name=channel][value='{channel}']").check()
    handle = page.locator(f"circle.handle.c{channel}[data-angle='{angle}']")
    handle.scroll_into_view_if_needed()
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    # Cleared after the channel's radio button is clicked (its own pointerup is not the drag's release).
    page.evaluate("window.cfTelemetry.shown.length = 0; window.cfMoves.length = 0; window.cfReleases.length = 0")
    # Each drag ends on its own curve, in each phase, so that no full refit is served from the store.
    step = (10 + 0.25 * d + 0.125 * phase_index) if extreme else (1.5 + 0.1 * d + 0.05 * phase_index)
    step *= 1 if extreme or d % 2 == 0 else -1
    page.mouse.move(x, y)
    page.mouse.down()
    for k in range(1, moves + 1):
        page.mouse.move(x, y + step * k)
        page.wait_for_timeout(40)
    page.wait_for_timeout(150)
    page.mouse.up()
    page.wait_for_function(SETTLED, timeout=120_000)
    page.wait_for_timeout(100)
    shown = page.evaluate("window.cfTelemetry.shown")
    moves_at = page.evaluate("window.cfMoves")
    releases = page.evaluate("window.cfReleases")
    assert len(releases) == 1, f"one release a drag, got {len(releases)}"
    released = releases[0]
    live = [s for s in shown if s.get("live") == "page" and s["frameAt"]]
    final = [s for s in shown if not s.get("live") and s["frameAt"] and s["frameAt"] > released]
    parts = [trace(s) for s in live]
    latencies, missed = [], 0
    for t in moves_at:
        frames = [s["frameAt"] for s in live if s["editAt"] >= t]
        if frames:
            latencies.append(min(frames) - t)
        else:
            missed += 1
    page.click("#undo")
    page.wait_for_function(SETTLED, timeout=120_000)
    if not final:
        return latencies, missed, None, parts, None
    first = min(final, key=lambda s: s["frameAt"])
    return latencies, missed, first["frameAt"] - released, parts, release_trace(first, released)


# Where a live refit's time goes, step by step on the page's clock (ms): the move's event to its edit
# (the page's handler), the edit to the message posted, the message to the worker's start (the
# wait for the solve in flight and the message), the solve, its end to the answer handled on the
# page (the message back and the main thread's queue), the answer to the frame drawn (the wait for
# the next animation frame, the curve and the WebGL draw).
STEPS = ("event_to_edit_ms", "edit_to_post_ms", "post_to_solve_ms", "solve_ms", "solve_to_page_ms", "page_to_frame_ms")


def trace(s):
    marks = (s["moveAt"], s["editAt"], s["sentAt"], s["solveStart"], s["solveEnd"], s["fittedAt"], s["frameAt"])
    return [b - a for a, b in zip(marks, marks[1:])]


# Where the release's wait goes: the release to the full refit's request sent (a request in flight
# first), the request to its answer, of it the server's own fit (``timings.total``: the solves, the
# guard, the scores) and the rest (the queue for a worker, the store, the curves, the round trip),
# the answer to its frame drawn.
RELEASE_STEPS = ("release_to_sent_ms", "sent_to_answer_ms", "server_fit_ms", "answer_wait_ms", "answer_to_frame_ms")


def release_trace(s, released):
    server = s["serverMs"] or 0.0
    answer = s["fittedAt"] - s["sentAt"]
    return [s["sentAt"] - released, answer, server, answer - server, s["frameAt"] - s["fittedAt"]]


def phase(browser, url, drags, moves, phase_index=0):
    """Gentle and extreme drags on one page: the figures of one phase."""
    page = editor(browser, url)
    load = [load_average()]
    out = {}
    for kind, extreme in (("gentle", False), ("extreme", True)):
        latencies, missed, releases, parts, release_parts = [], 0, [], [], []
        for d in range(drags):
            lat, miss, release, part, release_part = drag(page, d, moves, extreme, phase_index)
            latencies += lat
            missed += miss
            parts += part
            if release is not None:
                releases.append(release)
                release_parts.append(release_part)
            print(
                f"{kind} drag {d + 1}/{drags}: {len(lat)} moves, median {statistics.median(lat) if lat else 0:.0f} ms,"
                f" release {release or 0:.0f} ms",
                file=sys.stderr,
                flush=True,
            )
        out[kind] = {
            "move_to_frame_ms": summary(latencies),
            "moves_not_shown_live": missed,
            "release_to_final_ms": summary(releases),
            "latencies": latencies,
            **{step: summary([p[i] for p in parts]) for i, step in enumerate(STEPS)},
            "release": {step: summary([p[i] for p in release_parts]) for i, step in enumerate(RELEASE_STEPS)},
        }
    page.close()
    load.append(load_average())
    out["load_average"] = load
    # Over every drag of the phase, gentle and extreme together (the target's figure).
    out["all"] = {"move_to_frame_ms": summary(out["gentle"].pop("latencies") + out["extreme"].pop("latencies"))}
    return out


def busy_loops(count):
    """`count` busy-loop processes, pinned round the cores (two a core for count 2 x cores)."""
    cores = sorted(os.sched_getaffinity(0))
    code = "import os, sys; os.sched_setaffinity(0, {int(sys.argv[1])})\nwhile True: pass"
    return [subprocess.Popen([sys.executable, "-c", code, str(cores[k % len(cores)])]) for k in range(count)]


def wait_for_load(least, limit_s):
    """Wait (at most `limit_s`) until the 1-minute load average is at least `least`; the load reached."""
    end = time.monotonic() + limit_s
    while load_average() < least and time.monotonic() < end:
        time.sleep(2)
    return load_average()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--drags", type=int, default=20, help="gentle drags and extreme drags, each")
    parser.add_argument("--moves", type=int, default=20, help="pointer moves a drag")
    parser.add_argument(
        "--busy",
        type=int,
        default=2 * (os.cpu_count() or 1),
        help="busy-loop processes of the busy phase, pinned round the cores (default two a core)",
    )
    parser.add_argument(
        "--busy-load",
        type=float,
        default=4.0,
        help="the busy phase starts once the 1-minute load average is at least this (or after 5 min)",
    )
    args = parser.parse_args()
    load_at_start = load_average()
    figures: dict = {}
    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data", COATED_WARM_POOL="true") as server:
        url = server.url + "/"
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
            figures["idle"] = phase(browser, url, args.drags, args.moves)
            loops = busy_loops(args.busy)
            try:
                reached = wait_for_load(args.busy_load, 300)  # the 1-minute average follows within a few minutes
                print(f"busy phase: load average {reached:.1f}", file=sys.stderr, flush=True)
                figures["busy_load_reached"] = reached
                figures["busy"] = phase(browser, url, args.drags, args.moves, phase_index=1)
            finally:
                for loop in loops:
                    loop.kill()
                    loop.wait()
            browser.close()
    figures["busy_over_idle"] = {
        kind: figures["busy"][kind]["move_to_frame_ms"]["median_ms"]
        / figures["idle"][kind]["move_to_frame_ms"]["median_ms"]
        for kind in ("gentle", "extreme", "all")
    }
    print(f"{'pointer move -> frame of its refit (ms)':<44} {'median':>7} {'p90':>7} {'p99':>7} {'worst':>7} {'n':>5}")
    for name in ("idle", "busy"):
        for kind in ("gentle", "extreme", "all"):
            s = figures[name][kind]["move_to_frame_ms"]
            print(
                f"{name + ', ' + kind:<44} {s['median_ms']:>7.1f} {s['p90_ms']:>7.1f} {s['p99_ms']:>7.1f}"
                f" {s['worst_ms']:>7.1f} {s['n']:>5}"
            )
    print(f"\n{'release -> frame of the full refit (ms)':<44} {'median':>7} {'p90':>7} {'worst':>7} {'n':>5}")
    for name in ("idle", "busy"):
        for kind in ("gentle", "extreme"):
            s = figures[name][kind]["release_to_final_ms"]
            print(
                f"{name + ', ' + kind:<44} {s['median_ms']:>7.0f} {s['p90_ms']:>7.0f} {s['worst_ms']:>7.0f} {s['n']:>5}"
            )
    print(f"\n{'the release (ms, median / p90)':<17}" + "".join(f"{step[:-3]:>20}" for step in RELEASE_STEPS))
    for name in ("idle", "busy"):
        for kind in ("gentle", "extreme"):
            f = figures[name][kind]["release"]
            print(
                f"{name + ', ' + kind:<17}"
                + "".join(f"{f[k]['median_ms']:>11.0f}/{f[k]['p90_ms']:>7.0f} " for k in RELEASE_STEPS)
            )
    print(f"\n{'a live refit (ms, median / p99)':<17}" + "".join(f"{step[:-3]:>17}" for step in STEPS))
    for name in ("idle", "busy"):
        for kind in ("gentle", "extreme"):
            f = figures[name][kind]
            print(
                f"{name + ', ' + kind:<17}"
                + "".join(f"{f[k]['median_ms']:>8.1f}/{f[k]['p99_ms']:>7.1f} " for k in STEPS)
            )
    print(f"\nbusy / idle (median): {figures['busy_over_idle']}")
    print(
        f"load average: idle {figures['idle']['load_average']}, busy {figures['busy']['load_average']}"
        f" on {os.cpu_count()} cores"
    )
    write_result(
        "editor_live_latency", figures, load_at_start, busy_processes=args.busy, drags=args.drags, moves=args.moves
    )


if __name__ == "__main__":
    main()
