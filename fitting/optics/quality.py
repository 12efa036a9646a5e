"""
Data quality: gaps and outliers inside the visible range
========================================================

Coverage (:func:`fitting.optics.nk.visible_coverage`) looks at the ends of
the data only. Linear interpolation across a gap inside 360-830 nm invents
the metal's colour there: an Au file without samples between 471 and 659 nm
fits its own interpolation to about 0.1 Delta E while it is about 6 away
from the real metal.

-   :data:`DEFAULT_MAX_GAP_NM`: the largest spacing of samples inside the
    visible range accepted by default.
-   :func:`visible_gaps`: the spacings of the samples inside the visible
    range, widest first.
-   :func:`check_gaps`: refuse data with a gap wider than the limit, naming
    it; or, with the limit relaxed past the default, the warning to carry.
-   :data:`OUTLIER_DECADES`, :func:`find_outliers`, :func:`outlier_warnings`:
    isolated samples whose *n* or *k* is off the line through their
    neighbours by more than a factor of ten (a typing or unit error: metals'
    *n* and *k* change smoothly between samples), named with their wavelength.
-   :data:`UNCERTAIN_GAP_NM`: the gap from which a fit reports how far its
    figure can be off (:func:`fitting.fits.fit_quality.data_uncertainty`).

Why 120 nm: it is the widest spacing in the curated library (118 nm, Mo, Pb
and Ta), so every curated data set passes, and no wider: a gap hides what
the metal does inside it. ``benchmarks/data_gaps.py`` removes a window of
each width at every position of 380-810 nm from each library conductor and
scores the reference against the full data's (12 angles x 3 eta_i, 1 nm,
``benchmarks/results/data_gaps.json``): the worst Delta E 2000 over the
library is 4.5 at 60 nm, 10.3 at 100 nm and 12.1 at 120 nm (Cu, its
absorption edge), and the conductors moved by more than 2 are 2 at 60 nm,
8 at 100 nm, 11 at 120 nm. Metals' n, k vary on the scale of their
interband edges, 50-100 nm wide (Au 470-550 nm, Cu 560-620 nm): the curated
data already sample them as coarsely as this, and a wider gap can hide one
entirely. Data that need more (sparse measurements) are fitted
only when the caller relaxes the limit, with a warning in the result and
the pack's provenance.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..domain import VISIBLE_RANGE_NM

__all__ = [
    "DEFAULT_MAX_GAP_NM",
    "UNCERTAIN_GAP_NM",
    "OUTLIER_DECADES",
    "visible_gaps",
    "check_max_gap",
    "check_gaps",
    "find_outliers",
    "outlier_warnings",
]

DEFAULT_MAX_GAP_NM: float = 120.0
"""Largest spacing of samples inside 360-830 nm accepted by default (see the module docstring)."""


UNCERTAIN_GAP_NM: float = 60.0
"""From this widest gap inside 360-830 nm a fit reports the uncertainty of
its figure: a 60 nm window moves some library conductors' reference by
more than 2 Delta E 2000 (``benchmarks/results/data_gaps.json``)."""

OUTLIER_DECADES: float = 1.0
"""A sample is an outlier when its *n* or *k* lies more than this many
decades (a factor of ten) off the line, in log10, through its two
neighbours, and further off than the neighbours are from each other."""

_FLOOR = {"n": 1e-3, "k": 1e-2}  # below these, n and k do not move the colour: no decades counted


def check_max_gap(max_gap_nm) -> float:
    """A largest allowed gap in nm: a number > 0 (infinity turns the check off)."""
    try:
        value = float(max_gap_nm)
    except (TypeError, ValueError):
        raise ValueError(f"`max_gap_nm` must be a number > 0, got {max_gap_nm!r}") from None
    if not value > 0:
        raise ValueError(f"`max_gap_nm` must be a number > 0, got {max_gap_nm!r}")
    return value


def visible_gaps(wavelength_nm, visible_range_nm=VISIBLE_RANGE_NM) -> list[tuple[float, float]]:
    """
    ``(from, to)`` in nm of the spacings between consecutive samples that
    lie inside ``visible_range_nm`` (clipped to it), widest first; the ends
    beyond the data are coverage's, not gaps.
    """
    w = np.asarray(wavelength_nm, dtype=np.float64)
    lo, hi = visible_range_nm
    a, b = np.clip(w[:-1], lo, hi), np.clip(w[1:], lo, hi)
    keep = b > a
    gaps = sorted(zip(a[keep].tolist(), b[keep].tolist()), key=lambda g: g[0] - g[1])
    return [(float(x), float(y)) for x, y in gaps]


def check_gaps(nk, max_gap_nm: float = DEFAULT_MAX_GAP_NM) -> list[str]:
    """
    Refuse ``nk`` (a :class:`fitting.optics.nk.SpectralNK`) when a gap
    between its samples inside 360-830 nm is wider than ``max_gap_nm``;
    return the warnings to carry when ``max_gap_nm`` is relaxed past
    :data:`DEFAULT_MAX_GAP_NM` and the data use it (else none).

    Raises
    ------
    ValueError
        Naming the widest gap and the limit.
    """
    limit = check_max_gap(max_gap_nm)
    gaps = visible_gaps(nk.wavelength_nm)
    if not gaps:
        return []
    a, b = gaps[0]
    if b - a > limit:
        raise ValueError(
            f"`wavelength_nm` must have no gap wider than {limit:g} nm inside "
            f"{VISIBLE_RANGE_NM[0]:.0f}-{VISIBLE_RANGE_NM[1]:.0f} nm, the data have no samples "
            f"between {a:g} and {b:g} nm ({b - a:g} nm); relax `max_gap_nm` to fit them anyway"
        )
    if b - a > DEFAULT_MAX_GAP_NM:
        return [
            f"sparse data: no samples between {a:g} and {b:g} nm ({b - a:g} nm, more than "
            f"the default largest gap {DEFAULT_MAX_GAP_NM:g} nm); the colour there is interpolated"
        ]
    return []


def find_outliers(nk, decades: float = OUTLIER_DECADES) -> list[dict]:
    """
    The isolated outliers of ``nk`` among the samples a fit uses (inside
    360-830 nm and the nearest beyond each end): ``{"field", "wavelength_nm",
    "value", "expected", "decades"}`` each, in wavelength order. Each value
    is compared in log10 (floored where *n* or *k* no longer moves the
    colour) with the line through its two neighbours (at an end: the line
    through the next two).
    """
    w = np.asarray(nk.wavelength_nm, dtype=np.float64)
    lo, hi = VISIBLE_RANGE_NM
    first = max(int(np.searchsorted(w, lo, side="right")) - 1, 0)
    last = min(int(np.searchsorted(w, hi, side="left")), w.size - 1)
    found: list[dict[str, Any]] = []
    if w.size < 3:
        return found
    for label in ("n", "k"):
        values = np.asarray(getattr(nk, label), dtype=np.float64)
        logs = np.log10(np.maximum(values, _FLOOR[label]))
        for i in range(first, last + 1):
            a, b = (i - 1, i + 1) if 0 < i < w.size - 1 else ((i + 1, i + 2) if i == 0 else (i - 2, i - 1))
            expected = logs[a] + (logs[b] - logs[a]) * (w[i] - w[a]) / (w[b] - w[a])
            off = logs[i] - expected
            if abs(off) > decades and abs(off) > abs(logs[b] - logs[a]):
                found.append(
                    {
                        "field": label,
                        "wavelength_nm": float(w[i]),
                        "value": float(values[i]),
                        "expected": float(10.0**expected),
                        "decades": float(abs(off)),
                    }
                )
    return sorted(found, key=lambda o: (o["wavelength_nm"], o["field"]))


def outlier_warnings(nk, decades: float = OUTLIER_DECADES) -> list[str]:
    """The warning a fit carries for each outlier of :func:`find_outliers`."""
    return [
        f"outlier: {o['field']} = {o['value']:.4g} at {o['wavelength_nm']:g} nm is "
        f"{o['decades']:.1f} decades off its neighbours' {o['expected']:.4g}; check the data there"
        for o in find_outliers(nk, decades)
    ]
