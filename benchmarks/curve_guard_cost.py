"""
What the both-grid curve guard costs: the full curve refit's time, now against a commit before.

The default refit (:func:`fitting.fits.curves.fit_curves`, what the editor runs on release)
of six edits of ``benchmarks/curve_edits_hard.py`` (three gentle, three extreme), timed in two
worker processes, one running this checkout's ``fitting`` and one a ``git archive`` of
``fitting`` at the commit named (default: the one before the guard judged two grids), taking
turns edit by edit for ``--rounds`` rounds, so that both see the same load. The record gives
each edit's median seconds before and now (wall, and the worker's CPU: its own work whatever
else the machine does), their ratios, and the medians over the edits.

Writes benchmarks/results/curve_guard_cost.json.

Usage: python benchmarks/curve_guard_cost.py [--before COMMIT] [--rounds N]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402

BEFORE = "b4bb5aa"
"""The last commit whose curve guard judged the angle grid alone."""

EDITS = (
    "Pd blue lift",
    "W gentle step",
    "Co red crossing green",
    "Al two tints",
    "Au red pulled to 0.1",
    "Ni steep red step",
)

_WORKER = """
import json, sys, time
sys.path.insert(0, sys.argv[1]); sys.path.insert(1, sys.argv[2])
from benchmarks.curve_edits_hard import EDITS, edit_curve
from fitting import curve_base_from_nk, fit_curves, library_material
for line in sys.stdin:
    label, material, specs, _ = next(e for e in EDITS if e[0] == line.strip())
    base = curve_base_from_nk(library_material(material), (1.0, 2.5))
    curves = [edit_curve(base, eta, *spec) for eta, *spec in specs]
    t0, c0 = time.perf_counter(), time.process_time()
    fit_curves(curves, base)
    print(json.dumps([time.perf_counter() - t0, time.process_time() - c0]), flush=True)
"""


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--before", default=BEFORE)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    load = load_average()
    with tempfile.TemporaryDirectory() as old:
        archive = subprocess.run(
            ["git", "archive", args.before, "fitting"], cwd=ROOT, check=True, capture_output=True
        ).stdout
        subprocess.run(["tar", "-x", "-C", old], input=archive, check=True)
        workers = {
            name: subprocess.Popen(
                [sys.executable, "-c", _WORKER, path, str(ROOT)],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                text=True,
                cwd=ROOT,
            )
            for name, path in (("before", old), ("now", str(ROOT)))
        }
        times = {edit: {"before": [], "now": []} for edit in EDITS}
        cpu = {edit: {"before": [], "now": []} for edit in EDITS}
        for r in range(args.rounds):
            for edit in EDITS:
                for name in ("before", "now") if r % 2 == 0 else ("now", "before"):
                    worker = workers[name]
                    worker.stdin.write(edit + "\n")
                    worker.stdin.flush()
                    wall, seconds = json.loads(worker.stdout.readline())
                    times[edit][name].append(wall)
                    cpu[edit][name].append(seconds)
            print(
                f"round {r + 1}: "
                + ", ".join(f"{e} {times[e]['before'][-1]:.1f} / {times[e]['now'][-1]:.1f} s" for e in EDITS),
                flush=True,
            )
        for worker in workers.values():
            worker.stdin.close()
            worker.wait(timeout=60)
    rows = [
        {
            "edit": e,
            "before_s": float(np.median(t["before"])),
            "now_s": float(np.median(t["now"])),
            "ratio": float(np.median(t["now"]) / np.median(t["before"])),
            "before": t["before"],
            "now": t["now"],
            "before_cpu_s": float(np.median(cpu[e]["before"])),
            "now_cpu_s": float(np.median(cpu[e]["now"])),
            "cpu_ratio": float(np.median(cpu[e]["now"]) / np.median(cpu[e]["before"])),
        }
        for e, t in times.items()
    ]
    figures = {
        "before_commit": args.before,
        "rounds": args.rounds,
        "edits": len(rows),
        "before_median_s": float(np.median([r["before_s"] for r in rows])),
        "now_median_s": float(np.median([r["now_s"] for r in rows])),
        "ratio_median": float(np.median([r["ratio"] for r in rows])),
        "ratio_worst": max(r["ratio"] for r in rows),
        "before_cpu_median_s": float(np.median([r["before_cpu_s"] for r in rows])),
        "now_cpu_median_s": float(np.median([r["now_cpu_s"] for r in rows])),
        "cpu_ratio_median": float(np.median([r["cpu_ratio"] for r in rows])),
        "cpu_ratio_worst": max(r["cpu_ratio"] for r in rows),
    }
    path = write_result("curve_guard_cost", figures, load, rows=rows)
    print(f"wrote {path}: {figures}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
