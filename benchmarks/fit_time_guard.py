"""
Fit time with the max guard against the pipeline before it
===========================================================

Issue 21 asks that guarding the max keeps the fit time within 1.5x of the
pipeline before it ("today's", 18-25 ms median). This runs the library's
fit times (``benchmarks/worst_case_fits.py --timing-only``: CPU time of
``fit_material`` with its defaults, one BLAS thread, median of
``--repeats`` per conductor, median over the 22) of a checkout of
``--before`` (by default 51b944e, the commit before the guard, b7362fd)
and of this checkout, alternately for ``--rounds`` rounds on the same
machine, so that drifting load and CPU steal land on both. Records each
round's medians, their ratio, and the ratio of the medians over the
rounds in benchmarks/results/fit_time_guard.json.

Usage: python benchmarks/fit_time_guard.py [--before REV] [--rounds 3] [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402

BEFORE = "51b944e"
"""The last commit before the max guard (b7362fd): the pipeline issue 21 calls today's."""


def timings(root: Path, repeats: int) -> dict:
    """One ``worst_case_fits.py --timing-only`` run importing ``fitting`` from ``root``."""
    out = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "worst_case_fits.py"), "--timing-only", "--root", str(root),
         "--repeats", str(repeats)],
        cwd=tempfile.gettempdir(), check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--before", default=BEFORE, help=f"the commit to compare against (default {BEFORE})")
    parser.add_argument("--rounds", type=int, default=3, help="alternations of before and after")
    parser.add_argument("--repeats", type=int, default=5, help="timing repeats of each fit")
    args = parser.parse_args(argv)
    load_start = load_average()
    rounds = []
    with tempfile.TemporaryDirectory() as tmp:
        before = Path(tmp) / "before"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(before), args.before],
                       check=True, capture_output=True)
        try:
            print(f"{'round':>5} {'before ms':>10} {'after ms':>9} {'ratio':>6} {'load':>5}")
            for i in range(args.rounds):
                a = timings(before, args.repeats)
                b = timings(ROOT, args.repeats)
                ratio = b["median_ms"] / a["median_ms"]
                rounds.append({"before": a, "after": b, "ratio": ratio})
                print(f"{i + 1:5d} {a['median_ms']:10.1f} {b['median_ms']:9.1f} {ratio:6.2f} "
                      f"{os.getloadavg()[0]:5.2f}", flush=True)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(before)],
                           check=False, capture_output=True)
    before_ms = float(np.median([r["before"]["median_ms"] for r in rounds]))
    after_ms = float(np.median([r["after"]["median_ms"] for r in rounds]))
    ratios = [r["ratio"] for r in rounds]
    figures = {"before_commit": args.before, "before_median_ms": before_ms, "after_median_ms": after_ms,
               "ratio": after_ms / before_ms, "ratio_min": min(ratios), "ratio_max": max(ratios),
               "rounds": len(rounds)}
    print(json.dumps(figures, indent=1))
    print("recorded:", write_result("fit_time_guard", figures, load_start, repeats=args.repeats,
                                    runs=rounds))
    return 0


if __name__ == "__main__":
    sys.exit(main())
