"""
Per-channel index for the exact RGB conductor
=============================================

How the per-channel complex index :math:`(n_c, k_c)` of
:func:`fitting.models.rgb_conductor.rgb_fresnel_conductor` is chosen from
measured data: measured data give *n*, *k* per wavelength, not per channel,
and there is no unique projection. Here :math:`(n_c, k_c)` are the values
that make the exact Fresnel equations in air (eta_i = 1) reproduce channel
*c* of the spectral reference in linear ACEScg best in the least-squares
sense over cos theta in [0, 1]: the best an artist entering RGB *n*, *k*
could do, so the error left at eta_i > 1 is the error of the per-channel
approach itself, not of a poor choice of index.

-   :func:`rgb_nk`: per-channel :math:`(n_c, k_c)` of a material.

References
----------
Gulbrandsen, O. (2014). Artist friendly metallic Fresnel. JCGT, 3(4), 64-72.
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from ..colour.reference import reference_ACEScg
from ..domain import DEFAULT_MIN_COVERAGE
from ..optics.fresnel import fresnel_conductor
from ..optics.nk import SpectralNK

__all__ = ["RGB_NK_SAMPLES", "rgb_nk"]


RGB_NK_SAMPLES = 64
"""Values of cos theta, evenly over [0, 1], at which (n_c, k_c) are fitted."""


# Bounds of the per-channel index: n > 0 as for any SpectralNK; the upper
# bounds exceed every conductor of the library (n < 5, k < 12 in 360-830 nm).
_N_BOUNDS = (1.0e-3, 20.0)


_K_BOUNDS = (0.0, 50.0)


def rgb_nk(
    nk: SpectralNK, step_nm: float = 1.0, min_coverage: float = DEFAULT_MIN_COVERAGE
) -> tuple[np.ndarray, np.ndarray]:
    """
    Per-channel complex index of a material for the exact RGB Fresnel term.

    For each channel *c*, solves

    .. math::

        \\min_{n_c, k_c} \\sum_s \\bigl(F(\\mu_s, 1; n_c, k_c) - R_c(\\mu_s)\\bigr)^2

    with :math:`F` the exact unpolarised Fresnel reflectance in air,
    :math:`R_c` channel *c* of the spectral reference (linear ACEScg) and
    :math:`\\mu_s` :data:`RGB_NK_SAMPLES` values evenly over [0, 1], by the
    trust-region reflective method from the start :math:`n = 1`, :math:`k`
    from F0 (deterministic), within n in [1e-3, 20], k in [0, 50].

    Parameters
    ----------
    nk
        Measured spectral *n*, *k*.
    step_nm
        Spectral step of the reference (nm).
    min_coverage
        Smallest covered fraction of 360-830 nm accepted.

    Returns
    -------
    tuple
        ``n`` and ``k``, each shape (3,) for R, G, B.

    Raises
    ------
    ValueError
        For data covering too little of the visible range.
    """
    mu = np.linspace(0.0, 1.0, RGB_NK_SAMPLES)
    target = reference_ACEScg(nk, mu, 1.0, step_nm, min_coverage)
    n_out, k_out = np.empty(3), np.empty(3)
    for c in range(3):
        R = target[:, c]
        # At normal incidence with n = 1 the reflectance is k^2 / (4 + k^2).
        F0 = float(np.clip(R[-1], 0.0, 0.999))
        x0 = np.array([1.0, np.sqrt(4.0 * F0 / (1.0 - F0))])
        fit = least_squares(
            lambda x: fresnel_conductor(mu, 1.0, x[0], x[1]) - R,
            np.clip(x0, [_N_BOUNDS[0], _K_BOUNDS[0]], [_N_BOUNDS[1], _K_BOUNDS[1]]),
            bounds=([_N_BOUNDS[0], _K_BOUNDS[0]], [_N_BOUNDS[1], _K_BOUNDS[1]]),
            method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12,
        )
        n_out[c], k_out[c] = fit.x
    return n_out, k_out
