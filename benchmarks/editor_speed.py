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
    refit sent on release;
-   ``orbit fps``: preview frames drawn per second while the orbit changes
    every animation frame for 3 s (each frame read back, so it is rendered),
    studio environment, three-way split, at a 1024 x 768 viewport: smooth
    (roughness 0), rough (roughness 0.5: the split sum, every band) and
    rough under a rough clear coat (roughness 0.5, coat roughness 0.2),
    set through the page's controls; one page, the rows interleaved over
    three rounds of 2 s, the median of each.

Run: ``.venv/bin/python benchmarks/editor_speed.py [--drags 3] [--orbit-only]``
(``--orbit-only``: the three orbit rows alone, without the cold starts and
drags). The numbers depend on the machine's load (2 shared cores here).
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
from playwright.sync_api import sync_playwright  # noqa: E402

ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"]
READY = ("() => document.body.dataset.ready === 'true' && document.getElementById('preview').dataset.fit"
         " === document.getElementById('fit-id').textContent")


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


def drag_latencies(page, drags):
    out = []
    for d in range(drags):
        page.evaluate("window.cfTelemetry.shown.length = 0")
        handle = page.locator(f"circle.handle.c{d % 3}[data-angle='50']")
        page.locator(f"input[name=channel][value='{d % 3}']").check()
        box = handle.bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        page.mouse.move(x, y)
        page.mouse.down()
        for step in range(1, 41):
            page.mouse.move(x, y + (2 if d % 2 == 0 else -2) * step)
            page.wait_for_timeout(40)
        page.mouse.up()
        page.wait_for_function("document.getElementById('preview-state').hidden", timeout=60_000)
        page.wait_for_timeout(200)
        shown = page.evaluate("window.cfTelemetry.shown")
        if os.environ.get("EDITOR_SPEED_TRACE"):
            for s in shown:
                print({k: round(v - s["editAt"]) if k.endswith("At") and v else v for k, v in s.items()})
        out += [(s["curveAt"] - s["editAt"], s["frameAt"] - s["editAt"], s.get("live", False))
                for s in shown if s["frameAt"]]
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--drags", type=int, default=3, help="continuous drags measured")
    parser.add_argument("--orbit-only", action="store_true", help="only the orbit rows")
    args = parser.parse_args()
    first = second = None
    latencies = []
    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data", COATED_WARM_POOL="true") as server:
        url = server.url + "/"
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
            if not args.orbit_only:
                first = cold_start(browser, url)
                second = cold_start(browser, url)
                page = browser.new_page(viewport={"width": 1400, "height": 900})
                page.goto(url)
                page.wait_for_function(READY, timeout=120_000)
                # One edit first, as an artist's first touch: it warms the worker's base grid.
                page.locator("circle.handle.c1[data-angle='20']").focus()
                page.locator("input[name=channel][value='1']").check()
                page.locator("circle.handle.c1[data-angle='20']").focus()
                page.keyboard.press("ArrowUp")
                page.wait_for_function("document.getElementById('preview-state').hidden", timeout=60_000)
                latencies = drag_latencies(page, args.drags)
                page.close()
            orbits, size = orbit_fps(browser, url)
            browser.close()
    curve = [c for c, _, live in latencies if live]
    frame = [f for _, f, live in latencies if live]
    release = [f for _, f, live in latencies if not live]
    print(f"{'measure':<52} {'median':>9} {'p90':>9} {'n':>4}")
    if first is not None:
        print(f"{'cold start to editor + preview (s), first':<52} {first:>9.2f} {'':>9} {1:>4}")
        print(f"{'cold start to editor + preview (s), second':<52} {second:>9.2f} {'':>9} {1:>4}")
    if curve:
        print(f"{'drag edit -> refitted curve (ms)':<52} {statistics.median(curve):>9.0f} {percentile(curve, 0.9):>9.0f} {len(curve):>4}")
        print(f"{'drag edit -> WebGL frame of the refit (ms)':<52} {statistics.median(frame):>9.0f} {percentile(frame, 0.9):>9.0f} {len(frame):>4}")
    if release:
        print(f"{'release -> WebGL frame of the full refit (ms)':<52} {statistics.median(release):>9.0f} {percentile(release, 0.9):>9.0f} {len(release):>4}")
    for name, fps in orbits.items():
        label = f"orbit fps at 1024 x 768 (canvas {size[0]} x {size[1]}), {name}"
        print(f"{label:<52} {fps:>9.1f}")
    print(f"\nload average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
