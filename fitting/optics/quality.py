"""
Data quality: gaps inside the visible range
===========================================

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

import numpy as np

from ..domain import VISIBLE_RANGE_NM

__all__ = ["DEFAULT_MAX_GAP_NM", "visible_gaps", "check_max_gap", "check_gaps"]

DEFAULT_MAX_GAP_NM: float = 120.0
"""Largest spacing of samples inside 360-830 nm accepted by default (see the module docstring)."""


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
        return [f"sparse data: no samples between {a:g} and {b:g} nm ({b - a:g} nm, more than "
                f"the default largest gap {DEFAULT_MAX_GAP_NM:g} nm); the colour there is interpolated"]
    return []
