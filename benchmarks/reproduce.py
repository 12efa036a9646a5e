"""
The paper's Table 1 and Section 4.3, recorded
=============================================

``python -m fitting reproduce`` (:mod:`fitting.cli.reproduce`) with its
figures recorded: writes ``docs/results.md`` as the command does and
``benchmarks/results/reproduce.json`` (:mod:`benchmarks.record`): the mean
Delta E 2000 over the conductors per objective (float16 as shipped), each
baseline's, how many conductors ours beats every baseline on, each
conductor's mean and max, and the largest float32 to float16 increase per
eta_i of the Section 4.3 study. Accuracy figures: the load does not move them.

    .venv/bin/python benchmarks/reproduce.py [--materials Au,Cu]

With ``--materials`` (a subset, no shelf sample) the page goes to
``--output`` and nothing is recorded unless ``--record`` is given.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.cli.reproduce import reproduce, write_page  # noqa: E402
from fitting.cli.reproduce_worst import SHELF_SAMPLE  # noqa: E402
from fitting.optics.library import LIBRARY_NAMES  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--materials", help="comma-separated subset (default: all 22)")
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "results.md")
    parser.add_argument("--record", action="store_true", help="record a subset's figures too")
    args = parser.parse_args(argv)
    load0 = load_average()
    t0 = time.perf_counter()
    subset = tuple(args.materials.split(",")) if args.materials else None
    text, figures = reproduce(subset or LIBRARY_NAMES, () if subset else SHELF_SAMPLE)
    write_page(text, args.output)
    print(f"wrote {args.output}")
    if subset is None or args.record:
        print(f"wrote {write_result('reproduce', figures, load0, seconds=round(time.perf_counter() - t0, 1))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
