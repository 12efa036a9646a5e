"""
The database batch on a whole refractiveindex.info shelf
========================================================

Runs :func:`fitting.batch.run_batch` on every page of a shelf (default
``main``, 1,146 pages) with both model kinds, one worker (the other core is
left to the machine), and records what the README and docs/batch.md quote:
the pages fitted, skipped and failed, the wall time, and per model kind and
reported baseline the distribution of the per-page mean Delta E 2000 over
100 x 100 (eta_i 1-2.5) with the share of pages below adjusted Lazanyi::

    .venv/bin/python benchmarks/shelf_batch.py                 # about 40 min here
    .venv/bin/python benchmarks/shelf_batch.py --pages 'main/Au/*' --no-record

The same run as ``python -m fitting batch --shelf main --model
coated-conductor --model rgb-conductor -o DIR --workers 1``; the pack and
report stay in ``--output`` (a temporary directory by default).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.batch import run_batch, select_pages  # noqa: E402

KINDS = ("coated-conductor", "rgb-conductor")


def _table(summary: dict) -> str:
    lines = [
        "| model | pages | mean | median | p90 | max | below adjusted Lazanyi |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for name, entry in summary["delta_E_mean"].items():
        beats = entry.get("beats_lazanyi_adjusted")
        lines.append(
            f"| {name} | {entry['pages']} | {entry.get('mean', float('nan')):.3f} | "
            f"{entry.get('median', float('nan')):.3f} | {entry.get('p90', float('nan')):.3f} | "
            f"{entry.get('max', float('nan')):.2f} | {'' if beats is None else f'{100 * beats:.1f}%'} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shelf", default="main", help="the shelf (default main)")
    parser.add_argument("--pages", help="a SHELF/BOOK/PAGE glob instead of the whole shelf")
    parser.add_argument("--output", type=Path, help="directory for the pack and report (default: temporary)")
    parser.add_argument("--workers", type=int, default=1, help="worker processes (default 1)")
    parser.add_argument("--no-record", action="store_true", help="print only; do not write the record")
    args = parser.parse_args()
    pages = select_pages(pages_glob=args.pages) if args.pages else select_pages(shelf=args.shelf)
    load = load_average()
    with tempfile.TemporaryDirectory() as tmp:
        output = args.output or Path(tmp) / "run"
        started = time.perf_counter()
        result = run_batch(pages, output, kinds=KINDS, workers=args.workers, progress=False)
        wall = time.perf_counter() - started
        failed = {r["page"]: r.get("reason", "") for r in result.records if r["status"] == "failed"}
        skipped: dict[str, int] = {}
        for r in result.records:
            if r["status"] == "skipped":
                reason = str(r.get("reason", ""))
                reason = "coverage" if reason.startswith("covers") else reason.split(":")[0]
                skipped[reason] = skipped.get(reason, 0) + 1
    summary = result.summary
    print(
        f"{len(pages)} pages: {summary['fitted']} fitted, {summary['skipped']} skipped, "
        f"{summary['failed']} failed in {wall:.0f} s ({args.workers} worker)"
    )
    print(_table(summary))
    for page, reason in failed.items():
        print(f"failed: {page}: {reason}")
    if not args.no_record:
        figures = {
            "pages": summary["pages"],
            "fitted": summary["fitted"],
            "skipped": summary["skipped"],
            "failed": summary["failed"],
            "wall_s": round(wall, 1),
            "workers": args.workers,
            "delta_E_mean": summary["delta_E_mean"],
            "failed_pages": failed,
            "skipped_by_reason": skipped,
        }
        path = write_result(
            "shelf_batch", figures, load, kinds=list(KINDS), selection=args.pages or f"shelf {args.shelf}"
        )
        print(f"recorded in {path.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
