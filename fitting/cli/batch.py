"""
``python -m fitting batch``
===========================

Fit a selection of the refractiveindex.info database (:mod:`fitting.batch`)::

    python -m fitting batch --shelf main -o batch-main
    python -m fitting batch --book Au --model coated-conductor --workers 2
    python -m fitting batch --pages 'main/*/Johnson' --scheduler tcp://10.0.0.5:8786
    python -m fitting batch --page-list pages.txt

The output directory gets ``pack.cfpk``, ``pack.json``, ``report.csv``,
``report.json``, ``timings.csv`` and the journal; running the same command
again resumes an interrupted batch (or, when it finished, rewrites the same
outputs without fitting anything).

``python -m fitting catalogue`` rebuilds the conductor catalogue from the
shelf (:mod:`fitting.batch.catalogue`) into ``fitting/optics/catalogue.json``
(or ``-o FILE``); ``--check`` writes nothing and exits 1 when the file is not
what the installed database gives.
"""

from __future__ import annotations

import json
import sys

__all__ = ["add_batch_parser", "add_catalogue_parser"]


def _cmd_batch(args) -> int:
    from ..batch import read_page_list, run_batch, select_pages

    if args.page_list is not None:
        pages = select_pages(page_list=read_page_list(args.page_list))
    else:
        pages = select_pages(shelf=args.shelf, book=args.book, pages_glob=args.pages)
    from ..batch import DEFAULT_MODEL_KIND

    kinds = args.model or [DEFAULT_MODEL_KIND]
    print(f"batch: {len(pages)} pages, model kinds {', '.join(kinds)}, output {args.output}", file=sys.stderr)
    result = run_batch(
        pages,
        args.output,
        kinds=kinds,
        eta_i_range=args.eta_range,
        workers=args.workers,
        scheduler=args.scheduler,
        samples=args.samples,
        progress=not args.quiet,
    )
    s = result.summary
    print(
        f"batch: {s['fitted']} fitted, {s['skipped']} skipped, {s['failed']} failed; "
        f"{result.fitted_now} pages run now in {result.wall_s:.1f} s",
        file=sys.stderr,
    )
    print(json.dumps(s, indent=2))
    return 0


def add_batch_parser(sub, parse_eta_range) -> None:
    """
    Add the ``batch`` sub-command to an argparse sub-parser group;
    ``parse_eta_range`` is the ``--eta-range`` type of the main parser.
    """
    from ..batch import DEFAULT_MODEL_KIND, batch_kinds
    from ..domain import DEFAULT_ETA_I_RANGE

    p = sub.add_parser("batch", help="fit a selection of the refractiveindex.info database")
    chosen = p.add_mutually_exclusive_group()
    chosen.add_argument("--page-list", metavar="FILE", help="a file of SHELF/BOOK/PAGE names, one a line")
    p.add_argument("--shelf", help="every page of this shelf, e.g. main")
    p.add_argument("--book", help="every page of this book (BOOK on --shelf, default main, or SHELF/BOOK)")
    p.add_argument("--pages", metavar="GLOB", help="pages matching SHELF/BOOK/PAGE glob, e.g. 'main/*/Johnson'")
    p.add_argument(
        "--model",
        action="append",
        choices=sorted(batch_kinds()),
        metavar="KIND",
        help=f"model kind to fit, repeatable (default {DEFAULT_MODEL_KIND}; one of {', '.join(sorted(batch_kinds()))})",
    )
    p.add_argument(
        "--eta-range",
        type=parse_eta_range,
        default=DEFAULT_ETA_I_RANGE,
        metavar="LO:HI",
        help="eta_i domain of the fits (default 1:2.5)",
    )
    p.add_argument(
        "-o",
        "--output",
        default="batch-output",
        metavar="DIR",
        help="output directory with the journal (default batch-output)",
    )
    p.add_argument(
        "--workers", type=int, default=None, metavar="N", help="local worker processes (default: every core)"
    )
    p.add_argument(
        "--scheduler", metavar="ADDRESS", help="run on this dask.distributed scheduler instead, e.g. tcp://host:8786"
    )
    p.add_argument("--samples", type=int, default=100, metavar="N", help="scoring grid N x N (default the paper's 100)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_batch)


def _cmd_catalogue(args) -> int:
    from pathlib import Path

    from ..batch.catalogue import build_catalogue, catalogue_json
    from ..optics.catalogue import CATALOGUE_PATH

    path = Path(args.output) if args.output else CATALOGUE_PATH
    built = build_catalogue()
    body = catalogue_json(built)
    if args.check:
        current = path.is_file() and path.read_bytes() == body
        print(
            f"catalogue: {path} is {'current' if current else 'out of date (python -m fitting catalogue)'}",
            file=sys.stderr,
        )
        return 0 if current else 1
    path.write_bytes(body)
    print(f"catalogue: {len(built['materials'])} conductors written to {path}", file=sys.stderr)
    return 0


def add_catalogue_parser(sub) -> None:
    """Add the ``catalogue`` sub-command: rebuild (or ``--check``) the conductor catalogue."""
    p = sub.add_parser("catalogue", help="rebuild the conductor catalogue from the database shelf")
    p.add_argument("-o", "--output", metavar="FILE", help="write here (default fitting/optics/catalogue.json)")
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 when the file is out of date")
    p.set_defaults(func=_cmd_catalogue)
