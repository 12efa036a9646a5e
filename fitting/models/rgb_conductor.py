"""
RGB conductor model kind
========================

The model kind ``rgb-conductor``: the exact Fresnel equations of a conductor
evaluated once per RGB channel with one complex index :math:`n_c + i k_c`
per channel (Gulbrandsen 2014 and the ``conductor`` materials of RGB
renderers), seen from a coating of real index :math:`\\eta_i`, i.e. with the
relative index :math:`(n_c + i k_c)/\\eta_i` (as pbrt-v4's
``CoatedConductor`` divides the conductor's index by the interface's). It is
exact for a material whose index does not vary within a channel. Six
numbers per material, float16 in the pack.

Coefficient layout: ``coefficients[p, c]`` with parameter *p* in (n, k) and
channel *c* in (R, G, B); also the order of the 6 halves of the pack. The
GLSL mirror is ``cf_rgb_conductor`` / ``cf_rgb_conductor_packed`` in
``preview_shaders/glsl/cf_rgb_conductor.glsl`` (shader variants ``exact``
and ``rgb_conductor``). How n, k are chosen from measured data is a fit:
:mod:`fitting.fits.rgb_conductor`.

-   :data:`MODEL_KIND`, :data:`NK_PARAMETERS`.
-   :func:`check_rgb_conductor_coefficients`: shape (2, 3), finite, n > 0,
    k >= 0.
-   :func:`rgb_conductor_model`: the kind's reflectance, linear ACEScg.
-   :func:`rgb_fresnel_conductor`: the same from separate n and k arrays.

References
----------
Born, M., & Wolf, E. (1999). Principles of Optics (7th ed.), Section 1.5.
Gulbrandsen, O. (2014). Artist friendly metallic Fresnel. JCGT, 3(4), 64-72.
Pharr, M., Jakob, W., & Humphreys, G. (2023). Physically Based Rendering,
4th ed., Sections 9.3 and 14.3 (``FrComplex``, ``CoatedConductor``).
"""

from __future__ import annotations

import numpy as np

from ..domain import as_finite_array
from ..optics.fresnel import fresnel_conductor

__all__ = [
    "MODEL_KIND",
    "NK_PARAMETERS",
    "check_rgb_conductor_coefficients",
    "rgb_conductor_model",
    "rgb_fresnel_conductor",
]

MODEL_KIND = "rgb-conductor"
NK_PARAMETERS = ("n", "k")


def check_rgb_conductor_coefficients(coefficients) -> np.ndarray:
    """
    Validate per-channel indices of shape (2, 3): row 0 n > 0, row 1 k >= 0,
    every value finite.

    Raises
    ------
    ValueError
        If the shape is wrong or a value breaks its rule.
    """
    C = np.asarray(coefficients, dtype=np.float64)
    if C.shape != (2, 3):
        raise ValueError(
            f"`coefficients` of an rgb-conductor must have shape (2, 3) (parameter n/k, channel R/G/B), got {C.shape}"
        )
    if not np.all(np.isfinite(C)):
        raise ValueError("`coefficients` must be finite")
    if not np.all(C[0] > 0.0):
        raise ValueError(f"`coefficients` n must be > 0 in every channel, got {C[0].tolist()}")
    if not np.all(C[1] >= 0.0):
        raise ValueError(f"`coefficients` k must be >= 0 in every channel, got {C[1].tolist()}")
    return C


def rgb_conductor_model(cos_theta, eta_i, coefficients) -> np.ndarray:
    """
    Exact Fresnel reflectance per RGB channel under a coating.

    .. math::

        F_c(\\mu, \\eta_i) = F_{\\text{exact}}\\bigl(\\mu;\\ (n_c + i k_c)/\\eta_i\\bigr)

    Parameters
    ----------
    cos_theta
        :math:`\\mu = \\cos\\theta` in the coating, [0, 1] (clamped).
    eta_i
        Real index of the coating, >= 1, broadcast against ``cos_theta``.
    coefficients
        (2, 3) array: n and k per channel (:func:`check_rgb_conductor_coefficients`).

    Returns
    -------
    numpy.ndarray
        ``broadcast(cos_theta, eta_i).shape + (3,)``, linear ACEScg in
        [0, 1]; never NaN (grazing incidence gives 1, total internal
        reflection gives 1).
    """
    C = check_rgb_conductor_coefficients(coefficients)
    mu, eta = np.broadcast_arrays(as_finite_array("cos_theta", cos_theta), as_finite_array("eta_i", eta_i))
    return fresnel_conductor(mu[..., None], eta[..., None], C[0], C[1])


def rgb_fresnel_conductor(cos_theta, eta_i, n_rgb, k_rgb) -> np.ndarray:
    """
    :func:`rgb_conductor_model` from ``n_rgb`` and ``k_rgb``, shape (3,) each.

    Raises
    ------
    ValueError
        If a shape is not (3,), or n is not finite and > 0, or k not finite and >= 0.
    """
    n_rgb = np.asarray(n_rgb, dtype=np.float64)
    k_rgb = np.asarray(k_rgb, dtype=np.float64)
    if n_rgb.shape != (3,) or k_rgb.shape != (3,):
        raise ValueError(f"`n_rgb` and `k_rgb` must have shape (3,), got {n_rgb.shape} and {k_rgb.shape}")
    if not (np.all(np.isfinite(n_rgb)) and np.all(n_rgb > 0)):
        raise ValueError(f"`n_rgb` must be finite and > 0, got {n_rgb.tolist()}")
    if not (np.all(np.isfinite(k_rgb)) and np.all(k_rgb >= 0)):
        raise ValueError(f"`k_rgb` must be finite and >= 0, got {k_rgb.tolist()}")
    return rgb_conductor_model(cos_theta, eta_i, np.stack([n_rgb, k_rgb]))
