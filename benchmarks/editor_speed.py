"""
Editor speed in Chromium against a real server
==============================================

Debian's Chromium (headless, software WebGL2 through SwiftShader) drives
the editor served by a real ``python -m service`` process on 127.0.0.1:

-   ``cold start``: a fresh browser page to a usable editor with its WebGL
    preview drawn (``body[data-ready]`` and the canvas's ``data-fit`` equal
    to the fit on screen), on a server just started (its fitting pool
    warmed); then a second load of the same server;
-   ``drag step``: during a continuous drag of a control point (a pointer
    move every 40 ms), from the edit a live refit answers to its refitted
    curve drawn and to the first WebGL frame of that fit
    (``window.cfTelemetry``); median and p90 over the live refits of the
    drags; then, from the last edit of a drag, to the frame of the full
    refit sent on release; for gentle drags (a point moved 80 px over 40
    pointer moves) and extreme ones (Au's green pulled to 0.10 at 60
    degrees, an edit the model cannot follow, each on a fresh page) side by
    side, median and p99;
-   ``orbit fps``: preview frames drawn per second while the orbit changes
    every animation frame for 3 s (each frame read back, so it is rendered),
    studio environment, three-way split, at a 1024 x 768 viewport: smooth
    (roughness 0), rough (roughness 0.5: the split sum, every band) and
    rough under a rough clear coat (roughness 0.5, coat roughness 0.2),
    set through the page's controls; one page, the rows interleaved over
    three rounds of 2 s, the median of each.

Run: ``.venv/bin/python benchmarks/editor_speed.py [--drags 3] [--extreme 2] [--orbit-only | --drags-only]``
(``--orbit-only``: the three orbit rows alone, without the cold starts and
drags; ``--drags-only``: the drags alone). The numbers depend on the machine's load (2 shared cores here).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from conftest import server_process  # noqa: E402

from benchmarks.record import load_average, write_result  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402

ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-quic",
]
READY = (
    "() => document.body.dataset.ready === 'true' && document.getElementById('preview').dataset.fit"
    " === document.getElementById('fit-id').textContent"
)


def percentile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(round(q * (len(values) - 1))))]


def cold_start(browser, url):
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    t0 = time.perf_counter()
    page.goto(url)
    page.wait_for_function(READY, timeout=120_000)
    seconds = time.perf_counter() - t0
    page.close()
    return seconds


def drag_latencies(page, drags, extreme=False, variant=0):
    """
    (edit -> curve, edit -> frame, live) per refit shown during ``drags``
    drags: gentle (channel d % 3 at 50 degrees, 2 px per move), or
    ``extreme`` (green at 60 degrees pulled down, 4 + ``variant`` px per
    move, until the handle reads 0.10 or less: each variant ends on another
    curve, so that no full refit is served from the store).
    """
    out = []
    for d in range(drags):
        page.evaluate("window.cfTelemetry.shown.length = 0")
        channel, angle = (1, 60) if extreme else (d % 3, 50)
        handle = page.locator(f"circle.handle.c{channel}[data-angle='{angle}']")
        page.locator(f"input[name=channel][value='{channel}']").check()
        box = handle.bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(x, y)
        page.mouse.down()
        for step in range(1, 121 if extreme else 41):
            page.mouse.move(x, y + ((4 + variant) * step if extreme else (2 if d % 2 == 0 else -2) * step))
            page.wait_for_timeout(40)
            if extreme and float(handle.get_attribute("aria-valuenow")) <= 0.10:
                break
        page.mouse.up()
        page.wait_for_function("document.getElementById('preview-state').hidden", timeout=60_000)
        page.wait_for_timeout(200)
        shown = page.evaluate("window.cfTelemetry.shown")
        if os.environ.get("EDITOR_SPEED_TRACE"):
            for s in shown:
                print({k: round(v - s["editAt"]) if k.endswith("At") and v else v for k, v in s.items()})
        out += [
            (s["curveAt"] - s["editAt"], s["frameAt"] - s["editAt"], s.get("live", False))
            for s in shown
            if s["frameAt"]
        ]
    return out


ORBITS = {
    "smooth": {"roughness": "0", "coat": False},
    "rough 0.5": {"roughness": "0.5", "coat": False},
    "rough 0.5, coat 0.2": {"roughness": "0.5", "coat": True, "coat-roughness": "0.2"},
}

ORBIT_FPS = """(seconds) => new Promise((resolve) => {
    const ball = window.cfPreview, gl = ball.gl, pixel = new Uint8Array(4);
    const start = performance.now(), frames0 = ball.frames;
    function step(now) {
        const [yaw, pitch, distance] = ball.state.orbit;
        ball.set({ orbit: [yaw + 0.02, pitch, distance] });
        // Wait for the GPU each frame, so frames are counted only when rendered.
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
        if (now - start < 1000 * seconds) requestAnimationFrame(step);
        else resolve((ball.frames - frames0) / ((now - start) / 1000));
    }
    requestAnimationFrame(step);
})"""


def orbit_fps(browser, url, rounds=3, seconds=2.0):
    """
    Frames drawn per second while the orbit changes every animation frame,
    per row of ORBITS (set through the page's controls), in one page after
    its first fit; the rows interleaved over ``rounds``, the median kept.
    """
    page = browser.new_page(viewport={"width": 1024, "height": 768})
    page.goto(url)
    page.wait_for_function(READY, timeout=120_000)
    page.select_option("#environment", "studio")
    page.wait_for_timeout(1000)  # the first fit's worker goes idle
    runs = {name: [] for name in ORBITS}
    for _ in range(rounds):
        for name, controls in ORBITS.items():
            for control, value in controls.items():
                if isinstance(value, bool):
                    page.set_checked(f"#{control}", value)
                else:
                    page.fill(f"#{control}", value)
                    page.dispatch_event(f"#{control}", "input")
            # The split sum's textures (fetched on first use) are in before timing.
            page.evaluate("window.cfPreview.lightingReady()")
            runs[name].append(page.evaluate(ORBIT_FPS, seconds))
    size = page.evaluate("[window.cfPreview.canvas.width, window.cfPreview.canvas.height]")
    page.close()
    return {name: statistics.median(values) for name, values in runs.items()}, size


def fresh_editor(browser, url):
    """A new page on the editor, ready, after one edit (an artist's first touch: it warms the worker's base grid)."""
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    page.goto(url)
    page.wait_for_function(READY, timeout=120_000)
    page.locator("input[name=channel][value='1']").check()
    page.locator("circle.handle.c1[data-angle='20']").focus()
    page.keyboard.press("ArrowUp")
    page.wait_for_function("document.getElementById('preview-state').hidden", timeout=60_000)
    return page


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--drags", type=int, default=3, help="continuous drags measured")
    parser.add_argument("--extreme", type=int, default=2, help="extreme drags measured (a fresh page each)")
    parser.add_argument("--orbit-only", action="store_true", help="only the orbit rows")
    parser.add_argument("--drags-only", action="store_true", help="only the drag rows")
    args = parser.parse_args()
    load_at_start = load_average()
    figures: dict = {}
    first = second = None
    latencies, extremes, orbits = [], [], {}
    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data", COATED_WARM_POOL="true") as server:
        url = server.url + "/"
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
            if not args.orbit_only:
                if not args.drags_only:
                    first = cold_start(browser, url)
                    second = cold_start(browser, url)
                page = fresh_editor(browser, url)
                latencies = drag_latencies(page, args.drags)
                page.close()
                for variant in range(args.extreme):
                    page = fresh_editor(browser, url)
                    extremes += drag_latencies(page, 1, extreme=True, variant=variant)
                    page.close()
            if not args.drags_only:
                orbits, size = orbit_fps(browser, url)
            browser.close()
    if first is not None:
        print(f"{'measure':<52} {'median':>9} {'p90':>9} {'n':>4}")
        print(f"{'cold start to editor + preview (s), first':<52} {first:>9.2f} {'':>9} {1:>4}")
        print(f"{'cold start to editor + preview (s), second':<52} {second:>9.2f} {'':>9} {1:>4}")
        figures["cold_start_s"] = {"first": first, "second": second}
    if latencies:
        print(f"\n{'drags (ms)':<44} {'gentle':>8} {'p99':>7} {'n':>4}   {'extreme':>8} {'p99':>7} {'n':>4}")
        rows = [
            ("edit -> refitted curve, live", 0, True, "drag_to_curve_ms"),
            ("edit -> WebGL frame of the refit, live", 1, True, "drag_to_frame_ms"),
            ("release -> WebGL frame of the full refit", 1, False, "release_to_frame_ms"),
        ]
        for label, column, live, key in rows:
            cells = []
            for kind, runs in (("gentle", latencies), ("extreme", extremes)):
                values = [r[column] for r in runs if r[2] == live]
                if values:
                    figures.setdefault(key, {})[kind] = {
                        "median_ms": statistics.median(values),
                        "p90_ms": percentile(values, 0.9),
                        "p99_ms": percentile(values, 0.99),
                        "n": len(values),
                    }
                cells.append(
                    f"{statistics.median(values):>8.0f} {percentile(values, 0.99):>7.0f} {len(values):>4}"
                    if values
                    else f"{'-':>8} {'-':>7} {0:>4}"
                )
            print(f"{label:<44} {cells[0]}   {cells[1]}")
    for name, fps in orbits.items():
        label = f"orbit fps at 1024 x 768 (canvas {size[0]} x {size[1]}), {name}"
        print(f"{label:<52} {fps:>9.1f}")
        figures.setdefault("orbit_fps", {})[name] = fps
    print(f"\nload average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    write_result("editor_speed", figures, load_at_start)


if __name__ == "__main__":
    main()
