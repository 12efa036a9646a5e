"""
Spectral reference
==================

The exact reflectance of a conductor under a clear coating in linear ACEScg:
Fresnel per wavelength (:func:`fitting.optics.fresnel.fresnel_conductor`) integrated
with the weights of :func:`fitting.colour.colorimetry.spectral_to_ACEScg_weights`.

-   :func:`spectral_grid`: the wavelength nodes for a spectral step.
-   :func:`reference_ACEScg`: the reference at any (cos theta, eta_i).
-   :func:`evaluation_grid`: the paper's N x N scoring grid.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Sections 3.1 and 4.1.
"""

from __future__ import annotations

import functools

import numpy as np

from ..domain import (
    DEFAULT_ETA_I_RANGE, DEFAULT_MIN_COVERAGE, ETA_I_MIN, VISIBLE_RANGE_NM, as_finite_array, check_step_nm,
)
from ..optics.fresnel import fresnel_conductor
from ..optics.nk import SpectralNK, resample_nk
from .colorimetry import spectral_to_ACEScg_weights

__all__ = ["spectral_grid", "spectral_weights", "reference_ACEScg", "evaluation_grid"]


def spectral_grid(step_nm: float = 1.0) -> np.ndarray:
    """
    Wavelength nodes in nm from 360 to 830 with about ``step_nm`` spacing
    (the last interval is shortened to end exactly at 830 nm).
    """
    step = check_step_nm(step_nm)
    lo, hi = VISIBLE_RANGE_NM
    nodes = np.arange(lo, hi, step)
    return np.append(nodes, hi)


@functools.lru_cache(maxsize=16)
def _weights(step_nm: float) -> np.ndarray:
    W = spectral_to_ACEScg_weights(spectral_grid(step_nm))
    W.setflags(write=False)
    return W


def spectral_weights(step_nm: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The nodes (nm) and their 3 x N ACEScg weights, computed once per step."""
    return spectral_grid(step_nm), _weights(float(step_nm))


def reference_ACEScg(
    nk: SpectralNK,
    cos_theta,
    eta_i,
    step_nm: float = 1.0,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> np.ndarray:
    """
    Exact reflectance of ``nk`` seen from a coating of index ``eta_i`` in
    linear ACEScg.

    Parameters
    ----------
    nk
        Spectral optical constants of the conductor.
    cos_theta
        :math:`\\mu` in the coating, [0, 1].
    eta_i
        Real index of the coating, >= 1; broadcast against ``cos_theta``.
    step_nm
        Spectral step; 1 nm is the reference, coarser steps integrate the
        reflectance interpolated linearly between nodes.
    min_coverage
        Refuse data covering less of 360-830 nm than this fraction.

    Returns
    -------
    numpy.ndarray
        Shape ``broadcast(cos_theta, eta_i).shape + (3,)``, linear ACEScg;
        a perfect reflector is (1, 1, 1).
    """
    nodes, W = spectral_weights(step_nm)
    sampled = resample_nk(nk, nodes, min_coverage)
    mu, eta = np.broadcast_arrays(
        as_finite_array("cos_theta", cos_theta), as_finite_array("eta_i", eta_i)
    )
    if np.any(eta < ETA_I_MIN):
        raise ValueError(f"`eta_i` must be >= {ETA_I_MIN:g}, got {eta.min():g}")
    shape = mu.shape
    mu, eta = mu.reshape(-1, 1), eta.reshape(-1, 1)
    out = np.empty((mu.shape[0], 3))
    # Chunked so that memory stays bounded for large images.
    chunk = max(1, 2_000_000 // nodes.size)
    for start in range(0, mu.shape[0], chunk):
        stop = start + chunk
        R = fresnel_conductor(mu[start:stop], eta[start:stop], sampled.n, sampled.k)
        out[start:stop] = R @ W.T
    return out.reshape(shape + (3,))


def evaluation_grid(
    samples: int = 100, eta_i_range: tuple[float, float] = DEFAULT_ETA_I_RANGE
) -> tuple[np.ndarray, np.ndarray]:
    """
    The scoring grid of the paper (Section 4.1): ``samples`` values of
    :math:`\\mu` evenly over [0, 1] times ``samples`` values of eta_i evenly
    over ``eta_i_range``; returns (cos_theta, eta_i) each of shape (samples,
    samples) indexed [eta_i, cos_theta].
    """
    mu = np.linspace(0.0, 1.0, samples)
    eta = np.linspace(eta_i_range[0], eta_i_range[1], samples)
    E, M = np.meshgrid(eta, mu, indexing="ij")
    return M, E
