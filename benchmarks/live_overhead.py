"""
Live refit steps over HTTP: the service's own overhead and its pauses
=====================================================================

A real ``python -m service`` process on 127.0.0.1 (one fitting worker,
the pool warmed) and a plain HTTP client (no browser, so nothing else
competes for the cores): a drag of live refit steps (``POST
/api/v1/fits/from-curves`` with ``live``, ``start_fit`` the step before and
``curves_eta_i``, as the editor sends them) pulling Au's green curve at
eta_i 1.5 towards 0.10 at 60 degrees over ``--steps`` steps, 46 curve
samples, repeated ``--drags`` times (the first drag warms the caches and
is left out). Per step:

-   ``round trip``: the client's wall time of the request;
-   ``fit``: the worker's own time (the answer's ``timings.total``);
-   ``overhead``: the difference (HTTP, validation, the store's reads and
    the draft's write, the pool's hand-over, the curves of the answer).

With ``--gc-trace`` the server and its workers log every garbage
collection over 5 ms (a ``sitecustomize`` on their ``PYTHONPATH``), and the
record counts those that happened during the measured drags. Before the
heap was frozen after start-up (:func:`service.runtime.worker.freeze_heap`), full
collections of 60-86 ms in the server and 15-46 ms in a worker landed on
about one step in 160.

Run: ``.venv/bin/python benchmarks/live_overhead.py [--drags 4] [--steps 40]
[--gc-trace] [--output live_overhead]``; recorded in
``benchmarks/results/<output>.json``.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from conftest import server_process  # noqa: E402

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting import curve_base_from_nk, library_material  # noqa: E402

GC_TRACE = """
import gc, os, sys, time
_start = [0.0]
def _trace(phase, info):
    if phase == "start":
        _start[0] = time.perf_counter()
    elif (time.perf_counter() - _start[0]) * 1e3 > 5.0:
        sys.stderr.write(f"GC_PAUSE pid={os.getpid()} generation={info['generation']} "
                         f"ms={(time.perf_counter() - _start[0]) * 1e3:.1f}\\n")
gc.callbacks.append(_trace)
"""


def post(url: str, body: dict) -> dict:
    origin = url.split("/api/")[0]
    request = urllib.request.Request(
        url, data=json.dumps(body).encode(), headers={"Content-Type": "application/json", "Origin": origin}
    )
    with urllib.request.urlopen(request, timeout=60) as answer:
        return json.loads(answer.read())


def percentiles(values) -> dict[str, float]:
    values = np.asarray(values, dtype=np.float64)
    return {
        "p50": float(np.percentile(values, 50)),
        "p99": float(np.percentile(values, 99)),
        "max": float(values.max()),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--drags", type=int, default=4, help="drags (the first is a warm-up, not counted)")
    parser.add_argument("--steps", type=int, default=40, help="live steps per drag")
    parser.add_argument("--gc-trace", action="store_true", help="log the server's and workers' collections over 5 ms")
    parser.add_argument("--output", default="live_overhead", help="record name ('-': none)")
    args = parser.parse_args(argv)
    angle = np.linspace(0.0, 90.0, 46)
    mu = np.where(angle == 90.0, 0.0, np.cos(np.radians(angle)))
    rgb0 = curve_base_from_nk(library_material("Au")).rgb(mu, 1.5)
    bump = np.exp(-0.5 * ((angle - 60.0) / 9.0) ** 2)
    load_at_start = load_average()
    rows = {"round_trip": [], "fit": [], "overhead": []}
    with tempfile.TemporaryDirectory() as tmp:
        env = {"COATED_WARM_POOL": "true"}
        if args.gc_trace:
            (Path(tmp) / "sitecustomize.py").write_text(GC_TRACE)
            env["PYTHONPATH"] = tmp
        with server_process(Path(tmp) / "data", **env) as server:
            base = post(server.url + "/api/v1/fits", {"material": "Au"})
            route = server.url + "/api/v1/fits/from-curves?curves_eta_i=1.5&curves_samples=91"
            pauses_before = 0
            for drag in range(args.drags):
                if drag == 1:
                    pauses_before = server.log.read_text(errors="replace").count("GC_PAUSE")
                start = base["id"]
                for s in np.linspace(0.02 + 1e-3 * drag, 1.0, args.steps):  # another curve each drag
                    rgb = rgb0.copy()
                    rgb[:, 1] += s * (0.10 - rgb0[int(np.argmin(np.abs(angle - 60.0))), 1]) * bump
                    body = {
                        "name": "Live gold",
                        "base": {"fit": base["id"]},
                        "draft": True,
                        "live": True,
                        "start_fit": start,
                        "curves": [{"eta_i": 1.5, "angle_deg": angle.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}],
                    }
                    t0 = time.perf_counter()
                    fit = post(route, body)
                    wall = 1e3 * (time.perf_counter() - t0)
                    start = fit["id"]
                    if drag:
                        rows["round_trip"].append(wall)
                        rows["fit"].append(1e3 * fit["timings"]["total"])
                        rows["overhead"].append(wall - rows["fit"][-1])
            log = server.log.read_text(errors="replace")
    figures = {name: percentiles(values) for name, values in rows.items()}
    figures["steps"] = len(rows["round_trip"])
    if args.gc_trace:
        figures["gc_pauses_during_drags"] = log.count("GC_PAUSE") - pauses_before
    print(f"{'live step (ms)':<16} {'p50':>7} {'p99':>7} {'max':>7}   ({figures['steps']} steps)")
    for name in rows:
        f = figures[name]
        print(f"{name:<16} {f['p50']:>7.1f} {f['p99']:>7.1f} {f['max']:>7.1f}")
    if args.gc_trace:
        print(f"collections over 5 ms during the measured drags: {figures['gc_pauses_during_drags']}")
    if args.output != "-":
        print(
            "recorded:", write_result(args.output, figures, load_at_start, drags=args.drags, steps_per_drag=args.steps)
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
