"""
Spectral optical constants
==========================

The validated type for the measured complex index of refraction
:math:`n + i k` of a material, and its resampling onto the visible range.

-   :class:`SpectralNK`: spectral *n*, *k* with wavelengths in nm.
-   :func:`resample_nk`: *n*, *k* on a target wavelength grid, held flat past
    the ends of the data, with the covered fraction of the visible range.
-   :data:`VISIBLE_RANGE_NM` (from :mod:`fitting.domain`): the integration range of the reference, 360-830 nm.
-   :data:`MAX_NK`, :func:`check_nk_range`: the physical range of *n* and
    *k* the fit accepts where it uses them.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Section 3.1 (reference data evaluated from 360 to 830 nm).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..domain import DEFAULT_MIN_COVERAGE, VISIBLE_RANGE_NM, check_min_coverage

__all__ = [
    "VISIBLE_RANGE_NM",
    "DEFAULT_MIN_COVERAGE",
    "SpectralNK",
    "ResampledNK",
    "resample_nk",
    "visible_coverage",
    "MAX_NK",
    "check_nk_range",
]

MAX_NK = 1000.0
"""Largest *n* and *k* accepted at the samples a fit uses (those inside
360-830 nm and the nearest beyond each end): metals' visible *n* and *k*
stay under a few tens (the library's 22 under 10), so a value above this is
a unit or typing error, and every arithmetic of the reference, float32
included, stays finite up to it (the Fresnel terms square |n + ik|^2; 1e20
overflows float32). The CLI, the service and the scenes refuse the same
values through :func:`resample_nk`."""


def _format_value(value: float) -> str:
    return f"{value:.6g}"


def _check_1d_finite(name: str, values: Any) -> np.ndarray:
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"`{name}` must be a sequence of numbers: {error}") from None
    if array.ndim != 1:
        raise ValueError(f"`{name}` must be one-dimensional, got shape {array.shape}")
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        index = int(bad[0])
        raise ValueError(f"`{name}` must be finite, got {_format_value(array[index])} at index {index}")
    return array


@dataclass(frozen=True)
class SpectralNK:
    """
    Spectral complex index of refraction :math:`n + i k` of a material.

    Parameters
    ----------
    wavelength_nm
        Wavelength :math:`\\lambda` in nm, strictly increasing, finite.
    n
        Real part *n* of the index, > 0, finite.
    k
        Extinction coefficient *k*, >= 0, finite.
    name
        Display name of the material.
    source
        Citation of the data (carried into every output).

    Raises
    ------
    ValueError
        Naming the field, the broken rule and the offending value.
    """

    wavelength_nm: np.ndarray
    n: np.ndarray
    k: np.ndarray
    name: str = "unnamed"
    source: str = ""
    metadata: dict = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        wavelength = _check_1d_finite("wavelength_nm", self.wavelength_nm)
        n = _check_1d_finite("n", self.n)
        k = _check_1d_finite("k", self.k)
        if wavelength.size < 2:
            raise ValueError(f"`wavelength_nm` must hold at least 2 samples, got {wavelength.size}")
        for label, array in (("n", n), ("k", k)):
            if array.size != wavelength.size:
                raise ValueError(f"`{label}` must have one value per wavelength ({wavelength.size}), got {array.size}")
        if np.any(wavelength <= 0):
            index = int(np.flatnonzero(wavelength <= 0)[0])
            raise ValueError(f"`wavelength_nm` must be > 0, got {_format_value(wavelength[index])} at index {index}")
        steps = np.diff(wavelength)
        if np.any(steps <= 0):
            index = int(np.flatnonzero(steps <= 0)[0]) + 1
            raise ValueError(
                "`wavelength_nm` must be strictly increasing, got "
                f"{_format_value(wavelength[index])} after "
                f"{_format_value(wavelength[index - 1])} at index {index}"
            )
        if np.any(n <= 0):
            index = int(np.flatnonzero(n <= 0)[0])
            raise ValueError(f"`n` must be > 0, got {_format_value(n[index])} at index {index}")
        if np.any(k < 0):
            index = int(np.flatnonzero(k < 0)[0])
            raise ValueError(f"`k` must be >= 0, got {_format_value(k[index])} at index {index}")
        if not isinstance(self.name, str) or not self.name.strip():
            raise ValueError("`name` must be a non-empty string")
        for label, array in (("wavelength_nm", wavelength), ("n", n), ("k", k)):
            array.setflags(write=False)
            object.__setattr__(self, label, array)

    @property
    def wavelength_range_nm(self) -> tuple[float, float]:
        """Wavelength range of the data in nm."""
        return float(self.wavelength_nm[0]), float(self.wavelength_nm[-1])

    def content_key(self) -> bytes:
        """Bytes that identify the data (for content addressing)."""
        return b"".join(np.ascontiguousarray(a, dtype="<f8").tobytes() for a in (self.wavelength_nm, self.n, self.k))


def visible_coverage(
    wavelength_range_nm: tuple[float, float],
    visible_range_nm: tuple[float, float] = VISIBLE_RANGE_NM,
) -> float:
    """
    Fraction in [0, 1] of ``visible_range_nm`` covered by ``wavelength_range_nm``.
    """
    lo = max(wavelength_range_nm[0], visible_range_nm[0])
    hi = min(wavelength_range_nm[1], visible_range_nm[1])
    return max(0.0, hi - lo) / (visible_range_nm[1] - visible_range_nm[0])


@dataclass(frozen=True)
class ResampledNK:
    """*n* and *k* on a wavelength grid (nm), with the visible coverage in [0, 1]."""

    wavelength_nm: np.ndarray
    n: np.ndarray
    k: np.ndarray
    coverage: float


def resample_nk(
    nk: SpectralNK,
    wavelength_nm: np.ndarray,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> ResampledNK:
    """
    Linearly interpolate *n* and *k* onto ``wavelength_nm`` (nm).

    Data that stop short of the grid are held flat at their end values; the
    fraction of :data:`VISIBLE_RANGE_NM` the data cover is returned with the
    result and data covering less than ``min_coverage`` are refused.

    Raises
    ------
    ValueError
        If ``min_coverage`` is outside [0, 1], the data cover less of the
        visible range than ``min_coverage`` or hold a value outside
        :func:`check_nk_range`.
    """
    check_min_coverage(min_coverage)
    coverage = visible_coverage(nk.wavelength_range_nm)
    if coverage < min_coverage:
        lo, hi = nk.wavelength_range_nm
        raise ValueError(
            f"`wavelength_nm` must cover at least {min_coverage:.0%} of "
            f"{VISIBLE_RANGE_NM[0]:.0f}-{VISIBLE_RANGE_NM[1]:.0f} nm, the data "
            f"({_format_value(lo)}-{_format_value(hi)} nm) cover {coverage:.1%}"
        )
    check_nk_range(nk)
    wavelength_nm = np.asarray(wavelength_nm, dtype=np.float64)
    n = np.interp(wavelength_nm, nk.wavelength_nm, nk.n)
    k = np.interp(wavelength_nm, nk.wavelength_nm, nk.k)
    return ResampledNK(wavelength_nm, n, k, coverage)


def check_nk_range(nk: SpectralNK, limit: float = MAX_NK) -> None:
    """
    Refuse (``ValueError`` naming the field, the wavelength and the rule)
    an *n* or *k* above ``limit`` at a sample the reference uses: inside
    :data:`VISIBLE_RANGE_NM` or the nearest beyond each end.
    """
    w = nk.wavelength_nm
    lo, hi = VISIBLE_RANGE_NM
    first = max(int(np.searchsorted(w, lo, side="right")) - 1, 0)
    last = min(int(np.searchsorted(w, hi, side="left")), w.size - 1)
    for label, values in (("n", nk.n), ("k", nk.k)):
        used = values[first : last + 1]
        over = np.flatnonzero(used > limit)
        if over.size:
            i = first + int(over[0])
            raise ValueError(
                f"`{label}` must be at most {limit:g} inside {lo:.0f}-{hi:.0f} nm (the physical range "
                f"the fit scores in any precision), got {_format_value(values[i])} at "
                f"{_format_value(w[i])} nm"
            )
