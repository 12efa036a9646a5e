"""
A conductor under a clear coat, seen from air
=============================================

The physical stack air (index 1) / clear coat (real index :math:`\\eta`) /
conductor (:math:`n + i k`), seen from air at :math:`\\mu = \\cos\\theta`
(the view angle in air), with smooth parallel interfaces and a coat much
thicker than the coherence length (no thin-film interference):

-   the coat's own reflection :math:`R_{01}(\\mu)` at the air angle;
-   refraction into the coat, :math:`\\mu_c = \\sqrt{1 - (1 - \\mu^2)/\\eta^2}`;
-   the metal's reflection under the coat at the refracted angle,
    :math:`R_{12}(\\mu_c)`, exact Fresnel of the relative index
    :math:`(n + ik)/\\eta` (:func:`fitting.optics.fresnel.fresnel_conductor`);
-   the incoherent sum of the bounces between the two interfaces,

.. math::

    R_x = R_{01,x} + \\frac{(1 - R_{01,x})^2\\, R_{12,x}}{1 - R_{01,x} R_{12,x}},
    \\qquad R = \\tfrac12 (R_s + R_p),

per polarisation :math:`x \\in \\{s, p\\}` (a planar stack keeps the two
apart; the coat's reflectance seen from inside at :math:`\\mu_c` equals the
one from air at :math:`\\mu` by Stokes' relations, and its transmittance is
:math:`1 - R_{01}` both ways). With :math:`\\eta = 1` there is no coat:
:math:`R_{01} = 0`, :math:`\\mu_c = \\mu` and :math:`R` is the bare metal in
air.

-   :func:`fresnel_dielectric_sp`, :func:`fresnel_conductor_sp`: the two
    polarisations of the exact Fresnel reflectance.
-   :func:`refracted_cos`: cos theta inside the coat.
-   :func:`coated_stack`: the stack's reflectance seen from air, from the
    metal's n, k.
-   :func:`coated_stack_from_metal`: the same from the metal's (unpolarised)
    reflectance under the coat, for a model that gives only that.

Numeric policy as :mod:`fitting.optics.fresnel`: no raise on numeric input,
cos theta clamped to [0, 1], NaN propagates.

References
----------
Born, M., & Wolf, E. (1999). Principles of Optics (7th ed.), Sections 1.5
and 1.6 (Stokes' relations; the incoherent sum of multiple reflections).
Pharr, M., Jakob, W., & Humphreys, G. (2023). Physically Based Rendering,
4th ed., Section 9.3.
"""

from __future__ import annotations

import numpy as np

from ..domain import INDEX_LIMITS, as_float_array

__all__ = [
    "fresnel_dielectric_sp",
    "fresnel_conductor_sp",
    "refracted_cos",
    "coated_stack",
    "coated_stack_from_metal",
]


def _mu(cos_theta) -> np.ndarray:
    return np.clip(as_float_array("cos_theta", cos_theta), 0.0, 1.0)


def refracted_cos(cos_theta, eta) -> np.ndarray:
    """cos theta inside a coat of real index ``eta`` >= 1 of a ray at ``cos_theta`` in air."""
    mu = _mu(cos_theta)
    eta = np.clip(as_float_array("eta", eta), 1.0, INDEX_LIMITS[1])
    return np.sqrt(np.clip(1.0 - (1.0 - mu * mu) / (eta * eta), 0.0, 1.0))


def fresnel_dielectric_sp(cos_theta, eta) -> tuple[np.ndarray, np.ndarray]:
    """
    :math:`(R_s, R_p)` of air (index 1) over a clear medium of index ``eta``
    >= 1 at ``cos_theta`` in air; their mean is
    :func:`fitting.optics.fresnel.fresnel_dielectric` (1, eta).
    """
    mu = _mu(cos_theta)
    eta = np.clip(as_float_array("eta", eta), 1.0, INDEX_LIMITS[1])
    mu_t = refracted_cos(mu, eta)
    tiny = np.finfo(np.float64).tiny
    rs = (mu - eta * mu_t) / np.maximum(mu + eta * mu_t, tiny)
    rp = (eta * mu - mu_t) / np.maximum(eta * mu + mu_t, tiny)
    # Equal indices: no interface, even at grazing incidence (0 / 0 above).
    none = eta == 1.0
    return np.where(none, 0.0, rs * rs), np.where(none, 0.0, rp * rp)


def fresnel_conductor_sp(cos_theta, eta_i, n, k) -> tuple[np.ndarray, np.ndarray]:
    """
    :math:`(R_s, R_p)` of a conductor ``n + i k`` seen from a clear medium of
    index ``eta_i`` at ``cos_theta`` in that medium; their mean is
    :func:`fitting.optics.fresnel.fresnel_conductor`.
    """
    lo, hi = INDEX_LIMITS
    mu = _mu(cos_theta)
    n = np.clip(as_float_array("n", n), lo, hi)
    k = np.clip(as_float_array("k", k), 0.0, hi)
    eta_i = np.clip(as_float_array("eta_i", eta_i), lo, hi)
    eta = (n + 1j * k) / eta_i
    cos_t = np.sqrt(1.0 - (1.0 - mu * mu) / (eta * eta))
    tiny = np.finfo(np.float64).tiny
    den_s = np.maximum(np.abs(mu + eta * cos_t) ** 2, tiny)
    den_p = np.maximum(np.abs(eta * mu + cos_t) ** 2, tiny)
    Rs = np.abs(mu - eta * cos_t) ** 2 / den_s
    Rp = np.abs(eta * mu - cos_t) ** 2 / den_p
    return np.clip(Rs, 0.0, 1.0), np.clip(Rp, 0.0, 1.0)


def _stack(R01, R12) -> np.ndarray:
    # 1 - R01 R12 > 0 unless both are 1 (grazing on a perfect mirror), where
    # the sum is R01 = 1: the limit of the expression.
    den = 1.0 - R01 * R12
    T = 1.0 - R01
    return np.where(den > 0.0, R01 + T * T * R12 / np.where(den > 0.0, den, 1.0), R01)


def coated_stack(cos_theta, eta, n, k) -> np.ndarray:
    """
    Reflectance of air / coat ``eta`` / conductor ``n + i k`` seen from air.

    Parameters
    ----------
    cos_theta
        mu of the view direction in air, [0, 1] (clamped).
    eta
        Real index of the coat, >= 1 (1: no coat).
    n, k
        The conductor's index, broadcast against ``cos_theta`` (a spectrum,
        or one value per RGB channel).

    Returns
    -------
    numpy.ndarray
        Unpolarised reflectance in [0, 1], broadcast over the inputs.
    """
    mu = _mu(cos_theta)
    eta = np.clip(as_float_array("eta", eta), 1.0, INDEX_LIMITS[1])
    R01s, R01p = fresnel_dielectric_sp(mu, eta)
    R12s, R12p = fresnel_conductor_sp(refracted_cos(mu, eta), eta, n, k)
    return np.clip(0.5 * (_stack(R01s, R12s) + _stack(R01p, R12p)), 0.0, 1.0)


def coated_stack_from_metal(cos_theta, eta, metal) -> np.ndarray:
    """
    The stack of :func:`coated_stack` when only the metal's unpolarised
    reflectance under the coat is known: ``metal(cos_theta_in_coat)`` gives
    it, shape ``cos_theta.shape`` or ``cos_theta.shape + (C,)``. Both
    polarisations then see that reflectance (exact at normal incidence,
    where s and p agree; towards grazing the s / p split of the metal is
    not in the input).
    """
    mu = _mu(cos_theta)
    eta = float(np.clip(eta, 1.0, INDEX_LIMITS[1]))
    R12 = np.asarray(metal(refracted_cos(mu, eta)), dtype=np.float64)
    R01s, R01p = fresnel_dielectric_sp(mu, eta)
    if R12.ndim > mu.ndim:
        R01s, R01p = R01s[..., None], R01p[..., None]
    return np.clip(0.5 * (_stack(R01s, R12) + _stack(R01p, R12)), 0.0, 1.0)
