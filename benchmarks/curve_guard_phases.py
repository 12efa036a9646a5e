"""
Where a curve refit's time goes
===============================

The full curve refit (:func:`fitting.fits.curves.fit_curves`, what the
editor runs on release) of each edit of ``benchmarks/curve_edits_hard.py``
(its 12 edits and its 12 unseen ones), in this process with one BLAS
thread, its CPU seconds split by the guard's phases
(:mod:`fitting.fits.curves_guard`): the auditors' paper-method fits
(``auditors``), the capped constrained refits (``capped``), the minimax
over both auditors (``minimax``), the float16 polish of a kept twin of the
paper's method (``polish``), and the rest (the refit's own solves, the
target, the scores, the range proof). Each phase is timed where the guard
calls it; the median over ``--rounds`` of each.

The record's ``figures``: the edits whose guard ran the minimax and those
whose did not, each with its median and worst total and each phase's
median; over all edits, the median and worst share of each phase. ``rows``: each edit's seconds by
phase and the candidate kept.

Writes benchmarks/results/curve_guard_phases.json.

Usage: python benchmarks/curve_guard_phases.py [--rounds N] [--edits LABEL,...]
"""

from __future__ import annotations

import argparse
import contextlib
import statistics
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Iterator

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from threadpoolctl import threadpool_limits  # noqa: E402

import fitting.fits.curves_guard as guard  # noqa: E402
from benchmarks.curve_edits_hard import EDITS, UNSEEN, edit_curve  # noqa: E402
from fitting import curve_base_from_nk, fit_curves, library_material  # noqa: E402
from fitting.numerics import scipy_optimize  # noqa: E402
from benchmarks.record import load_average, write_result  # noqa: E402

PHASES = {
    "auditor_fits": "auditors",
    "constrained_refits": "capped",
    "minimax_fit": "minimax",
    "polish_float16": "polish",
}
"""The guard's calls timed (as :mod:`fitting.fits.curves_guard` names them) and the phase each is."""


@contextlib.contextmanager
def timed_phases(guard) -> Iterator[Counter]:
    """
    The guard's calls of :data:`PHASES` wrapped while inside, each adding its CPU seconds to the
    counter yielded (a generator's as it is consumed: the whole of it, as the guard consumes it).
    """
    spent: Counter = Counter()
    originals = {name: getattr(guard, name) for name in PHASES}

    def wrap(function, phase):
        def timed(*args, **kwargs):
            start = time.process_time()
            try:
                out = function(*args, **kwargs)
                return list(out) if hasattr(out, "__next__") else out
            finally:
                spent[phase] += time.process_time() - start

        return timed

    for name, phase in PHASES.items():
        setattr(guard, name, wrap(originals[name], phase))
    try:
        yield spent
    finally:
        for name, function in originals.items():
            setattr(guard, name, function)


def _row(edit, spent: Counter, rounds: int) -> dict:
    """One edit's refit, ``rounds`` times after one untimed: its median CPU seconds by phase."""
    label, material, specs, extreme = edit
    base = curve_base_from_nk(library_material(material))
    curves = [edit_curve(base, eta, *spec) for eta, *spec in specs]
    fit_curves(curves, base)  # the base's caches and this edit's first-use costs, as a warm worker has them
    runs = []
    for _ in range(rounds):
        spent.clear()
        start = time.process_time()
        result = fit_curves(curves, base)
        runs.append({"total": time.process_time() - start, **spent})
    phases = {phase: statistics.median(run.get(phase, 0.0) for run in runs) for phase in ("total", *PHASES.values())}
    phases["rest"] = max(phases["total"] - sum(phases[p] for p in PHASES.values()), 0.0)
    row = {
        "edit": label,
        "material": material,
        "extreme": extreme,
        "kept": result.metrics["guard"]["chosen"],
        "minimax_ran": phases["minimax"] > 0.0,
        **{f"{phase}_s": round(seconds, 4) for phase, seconds in phases.items()},
    }
    print(
        f"{label:40s} {row['total_s']:5.2f} s kept {row['kept']:22s} "
        + " ".join(f"{p} {row[p + '_s']:.2f}" for p in (*PHASES.values(), "rest")),
        flush=True,
    )
    return row


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--edits", default=None, help="labels of curve_edits_hard's edits, comma-separated")
    args = parser.parse_args(argv)
    threadpool_limits(limits=1, user_api="blas")
    scipy_optimize()  # imported once, as the service's workers have it
    edits = [e for e in (*EDITS, *UNSEEN) if args.edits is None or e[0] in args.edits.split(",")]
    if not edits:
        parser.error("--edits names none of curve_edits_hard's edits")
    load = load_average()
    with timed_phases(guard) as spent:
        rows = [_row(edit, spent, args.rounds) for edit in edits]

    def totals(selected):
        seconds = [r["total_s"] for r in selected]
        return {
            "edits": len(seconds),
            "median_s": statistics.median(seconds) if seconds else None,
            "worst_s": max(seconds) if seconds else None,
            "phases_median_s": {
                phase: statistics.median(r[f"{phase}_s"] for r in selected) if selected else None
                for phase in (*PHASES.values(), "rest")
            },
        }

    figures = {
        "rounds": args.rounds,
        "edits": len(rows),
        "with_minimax": totals([r for r in rows if r["minimax_ran"]]),
        "without_minimax": totals([r for r in rows if not r["minimax_ran"]]),
        "share": {
            phase: {
                "median": statistics.median(r[f"{phase}_s"] / r["total_s"] for r in rows),
                "worst": max(r[f"{phase}_s"] / r["total_s"] for r in rows),
            }
            for phase in (*PHASES.values(), "rest")
        },
    }
    path = write_result("curve_guard_phases", figures, load, rows=rows)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
