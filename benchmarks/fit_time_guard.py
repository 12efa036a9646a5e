"""
Fit time with the max guard against the pipeline before it
===========================================================

Guarding the max must keep the fit time within 1.5x of the
pipeline before it ("today's", 18-25 ms median). This times the library's
fits (CPU time of ``fit_material`` with its defaults, one BLAS thread, the
median of ``--repeats`` per conductor, then the median over the 22) of a
checkout of ``--before`` (by default 51b944e, the commit before the guard,
b7362fd) and of this checkout, in two processes that run side by side
and take turns conductor by conductor (the order swapped every round), so
that the machine's drifting load and CPU steal land on both alike: whole
runs in turn, as this benchmark timed before, moved one round's ratio by
up to 0.25 on this machine. Records each round's medians, their ratio and
the ratio of the medians over the rounds, and each conductor's own ratio
(and their median), in benchmarks/results/fit_time_guard.json.

``--output NAME`` records benchmarks/results/NAME.json instead: the same
comparison against another commit (``fit_solver_speed``: the lean
trust-region solver against the commit before it, 09bbd13).

Usage: python benchmarks/fit_time_guard.py [--before REV] [--rounds 5] [--repeats 5] [--output NAME]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.side_by_side import Side, checkout, serve  # noqa: E402

BEFORE = "51b944e"
"""The last commit before the max guard (b7362fd): the pipeline before the guard."""


def child(root: str, repeats: int) -> int:
    """One side: ``fitting`` from ``root``; each name read from stdin answered with its median CPU ms."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")
    sys.path.insert(0, root)
    from fitting import LIBRARY_NAMES, fit_material, library_material

    fit_material(library_material(LIBRARY_NAMES[0]))  # warm caches

    def answer(name: str) -> float:
        nk = library_material(name)
        times = []
        for _ in range(repeats):
            t = time.process_time()
            fit_material(nk)
            times.append(time.process_time() - t)
        return 1e3 * float(np.median(times))

    return serve(LIBRARY_NAMES, answer)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--before", default=BEFORE, help=f"the commit to compare against (default {BEFORE})")
    parser.add_argument("--rounds", type=int, default=5, help="rounds over the 22 conductors")
    parser.add_argument("--repeats", type=int, default=5, help="timing repeats of each fit")
    parser.add_argument(
        "--output",
        default="fit_time_guard",
        help="record to write, benchmarks/results/NAME.json (default fit_time_guard)",
    )
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        return child(args.child, args.repeats)
    load_start = load_average()
    rounds = []
    with checkout(args.before) as before_root:
        before = after = None
        try:
            before = Side(__file__, before_root, "--repeats", str(args.repeats))
            after = Side(__file__, ROOT, "--repeats", str(args.repeats))
            if before.names != after.names:
                raise SystemExit("the two checkouts have different libraries")
            print(f"{'round':>5} {'before ms':>10} {'after ms':>9} {'ratio':>6} {'load':>5}")
            for i in range(args.rounds):
                sides = (before, after) if i % 2 == 0 else (after, before)
                ms = {before.root: {}, after.root: {}}
                for name in before.names:
                    for side in sides:
                        ms[side.root][name] = side.ask(name)
                a, b = (float(np.median(list(ms[s.root].values()))) for s in (before, after))
                rounds.append(
                    {
                        "before": {"median_ms": a, "ms": ms[before.root]},
                        "after": {"median_ms": b, "ms": ms[after.root]},
                        "ratio": b / a,
                        "load": os.getloadavg()[0],
                    }
                )
                print(f"{i + 1:5d} {a:10.1f} {b:9.1f} {b / a:6.2f} {os.getloadavg()[0]:5.2f}", flush=True)
        finally:
            for side in (before, after):
                if side is not None:
                    side.close()
    before_ms = float(np.median([r["before"]["median_ms"] for r in rounds]))
    after_ms = float(np.median([r["after"]["median_ms"] for r in rounds]))
    ratios = [r["ratio"] for r in rounds]
    # Each conductor's own ratio (its medians over the rounds): where the
    # median over the 22 falls moves with which conductors the guard refits.
    own = {
        name: float(
            np.median([r["after"]["ms"][name] for r in rounds]) / np.median([r["before"]["ms"][name] for r in rounds])
        )
        for name in rounds[0]["before"]["ms"]
    }
    figures = {
        "before_commit": args.before,
        "before_median_ms": before_ms,
        "after_median_ms": after_ms,
        "ratio": after_ms / before_ms,
        "ratio_min": min(ratios),
        "ratio_max": max(ratios),
        "rounds": len(rounds),
        "conductor_ratio_median": float(np.median(list(own.values()))),
        "conductor_ratio_max": max(own.values()),
        "conductor_ratios": own,
    }
    print(json.dumps(figures, indent=1))
    print("recorded:", write_result(args.output, figures, load_start, repeats=args.repeats, runs=rounds))
    return 0


if __name__ == "__main__":
    sys.exit(main())
