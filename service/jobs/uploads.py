"""
The upload form's coverage rule
===============================

:func:`check_coverage`: an upload's ``min_coverage`` honoured. The service
fits no data covering less than :data:`fitting.domain.DEFAULT_MIN_COVERAGE`
of 360-830 nm (the reference holds the data flat past their ends, and past
10% of the range that would be a guess), so a form may ask for more, never
for less.
"""

from __future__ import annotations

from fitting.domain import DEFAULT_MIN_COVERAGE, VISIBLE_RANGE_NM
from fitting.optics.nk import SpectralNK, visible_coverage

__all__ = ["check_coverage"]

_RANGE = f"{VISIBLE_RANGE_NM[0]:.0f}-{VISIBLE_RANGE_NM[1]:.0f} nm"


def check_coverage(nk: SpectralNK, min_coverage: float | None) -> None:
    """
    ValueError unless ``min_coverage`` is None or in [DEFAULT_MIN_COVERAGE,
    1], and when the data ``nk`` cover less of 360-830 nm than it.
    """
    if min_coverage is None:
        return
    if not DEFAULT_MIN_COVERAGE <= min_coverage <= 1.0:
        raise ValueError(
            f"`min_coverage` must lie in [{DEFAULT_MIN_COVERAGE:g}, 1], got {min_coverage:g}: the "
            f"reference integrates {_RANGE} and the service fits no data covering less than "
            f"{DEFAULT_MIN_COVERAGE:.0%} of it (the rest is held flat at the data's ends)"
        )
    coverage = visible_coverage(nk.wavelength_range_nm)
    if coverage < min_coverage:
        lo, hi = nk.wavelength_range_nm
        raise ValueError(
            f"`min_coverage` is {min_coverage:.1%} of {_RANGE}, the data "
            f"({lo:g}-{hi:g} nm) cover {coverage:.1%}: nothing was fitted"
        )
