"""
Exact Fresnel reflectance
=========================

-   :func:`fresnel_conductor`: unpolarised reflectance of a conductor
    :math:`n + i k` seen from a clear dielectric of real index
    :math:`\\eta_i`, vectorised over any broadcastable shapes.
-   :func:`fresnel_dielectric`: the real-index special case in closed form.

Numeric policy (as pbrt-v4's ``FrComplex``): these kernels never raise on
numeric input and never return NaN for finite input. cos theta is clamped to
[0, 1] (a direction below the surface is grazing); indices and extinction
coefficients are clamped to :data:`fitting.domain.INDEX_LIMITS` (an index
<= 0 or a negative k is no material; past 1e8 the reflectance is 1 to 1e-8
and the clamp keeps the arithmetic inside float64). A NaN input gives NaN at
its position, so a bad value is seen rather than hidden; +/-inf is clamped
like any large value. Data are validated where they enter: ``SpectralNK``,
the readers, ``reference_ACEScg``, the CLI and the API.

References
----------
Born, M., & Wolf, E. (1999). Principles of Optics (7th ed.), Section 1.5.
Pharr, M., Jakob, W., & Humphreys, G. (2023). Physically Based Rendering,
4th ed., Section 9.3 (``FrComplex``).
"""

from __future__ import annotations

import numpy as np

from ..domain import INDEX_LIMITS, as_float_array

__all__ = ["fresnel_conductor", "fresnel_conductor_derivatives", "fresnel_dielectric"]


def fresnel_conductor(cos_theta, eta_i, n, k) -> np.ndarray:
    """
    Unpolarised Fresnel reflectance :math:`(R_s + R_p)/2` of a conductor.

    With the relative index :math:`\\eta = (n + i k)/\\eta_i`,
    :math:`\\cos\\theta_t = \\sqrt{1 - (1 - \\mu^2)/\\eta^2}` (principal
    branch) and

    .. math::

        r_s = \\frac{\\mu - \\eta\\cos\\theta_t}{\\mu + \\eta\\cos\\theta_t},
        \\quad
        r_p = \\frac{\\eta\\mu - \\cos\\theta_t}{\\eta\\mu + \\cos\\theta_t},
        \\quad
        R = \\tfrac12(|r_s|^2 + |r_p|^2).

    Parameters
    ----------
    cos_theta
        :math:`\\mu = \\cos\\theta` in the incident medium, [0, 1]; values
        outside are clamped.
    eta_i
        Real index of the incident (coating) medium, >= 1.
    n, k
        Real part and extinction coefficient of the conductor's index.

    Returns
    -------
    numpy.ndarray
        Reflectance in [0, 1], broadcast over the inputs. Never NaN for
        finite input (see the module docstring for the clamps): grazing
        incidence gives 1, total internal reflection (k = 0, eta_i > n) gives
        1, an index-matched interface gives 0. NaN in any input gives NaN.
    """
    lo, hi = INDEX_LIMITS
    # Clamped, not refused: see the module docstring. np.clip keeps NaN.
    mu = np.clip(as_float_array("cos_theta", cos_theta), 0.0, 1.0)
    n = np.clip(as_float_array("n", n), lo, hi)
    k = np.clip(as_float_array("k", k), 0.0, hi)
    eta_i = np.clip(as_float_array("eta_i", eta_i), lo, hi)
    eta = (n + 1j * k) / eta_i
    sin2_t = (1.0 - mu * mu) / (eta * eta)
    # Principal complex square root: for k = 0 past the critical angle the
    # argument is negative real, cos_t is imaginary and |r_s| = |r_p| = 1 (TIR).
    cos_t = np.sqrt(1.0 - sin2_t)
    eta_cos_t = eta * cos_t
    eta_mu = eta * mu
    num_s, den_s = mu - eta_cos_t, mu + eta_cos_t
    num_p, den_p = eta_mu - cos_t, eta_mu + cos_t
    # Both denominators vanish only for mu = 0 and eta = 1 (index matched at
    # grazing): there the interface does not exist and R is 0.
    tiny = np.finfo(np.float64).tiny
    R = 0.5 * (_abs2(num_s) / np.maximum(_abs2(den_s), tiny) + _abs2(num_p) / np.maximum(_abs2(den_p), tiny))
    return np.clip(R, 0.0, 1.0)


def fresnel_conductor_derivatives(cos_theta, eta_i, n, k) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    :func:`fresnel_conductor` and its exact derivatives in ``n`` and ``k``:
    ``(R, dR/dn, dR/dk)``, broadcast over the inputs (for least squares
    that fit n and k).

    :math:`r_s` and :math:`r_p` are analytic in :math:`\\eta = (n + ik)/\\eta_i`,
    so with :math:`D = \\bar r_s r_s' + \\bar r_p r_p'` (derivatives in
    :math:`\\eta`, from the same expressions as :func:`fresnel_conductor`),
    :math:`\\partial R/\\partial n = \\mathrm{Re}\\,D/\\eta_i` and
    :math:`\\partial R/\\partial k = -\\mathrm{Im}\\,D/\\eta_i`. Where a
    clamp of :func:`fresnel_conductor` holds (an index at its limits, R
    at 0 or 1) or :math:`\\cos\\theta_t = 0` (k = 0 at the critical
    angle, where R has no derivative) the derivatives are 0.
    """
    lo, hi = INDEX_LIMITS
    mu = np.clip(as_float_array("cos_theta", cos_theta), 0.0, 1.0)
    n_in, k_in = as_float_array("n", n), as_float_array("k", k)
    n, k = np.clip(n_in, lo, hi), np.clip(k_in, 0.0, hi)
    eta_i = np.clip(as_float_array("eta_i", eta_i), lo, hi)
    eta = (n + 1j * k) / eta_i
    s = 1.0 - mu * mu
    cos_t = np.sqrt(1.0 - s / (eta * eta))
    eta_cos_t = eta * cos_t
    eta_mu = eta * mu
    num_s, den_s = mu - eta_cos_t, mu + eta_cos_t
    num_p, den_p = eta_mu - cos_t, eta_mu + cos_t
    tiny = np.finfo(np.float64).tiny
    den_s2, den_p2 = np.maximum(_abs2(den_s), tiny), np.maximum(_abs2(den_p), tiny)
    R = 0.5 * (_abs2(num_s) / den_s2 + _abs2(num_p) / den_p2)
    with np.errstate(divide="ignore", invalid="ignore"):
        dcos_t = s / (eta**3 * cos_t)  # d cos_t / d eta
        # r_s' = -2 mu (eta cos_t)' / den_s^2 and r_p' = 2 mu (cos_t - eta cos_t') / den_p^2;
        # conj(r) r' = conj(num) r' den / |den|^2.
        D = np.conj(num_s) * (-2.0 * mu) * (cos_t + eta * dcos_t) / (den_s2 * den_s) + np.conj(num_p) * (2.0 * mu) * (
            cos_t - eta * dcos_t
        ) / (den_p2 * den_p)
    D = np.where(np.isfinite(D) & (cos_t != 0.0) & (R > 0.0) & (R < 1.0), D, 0.0) / eta_i
    dn = np.where((n_in >= lo) & (n_in <= hi), D.real, 0.0)
    dk = np.where((k_in >= 0.0) & (k_in <= hi), -D.imag, 0.0)
    return np.clip(R, 0.0, 1.0), dn, dk


def _abs2(z: np.ndarray) -> np.ndarray:
    """
    :math:`|z|^2` as :math:`\\operatorname{Re}(z)^2 + \\operatorname{Im}(z)^2`:
    the square of ``np.abs`` (a hypot) is the same value to rounding and
    takes longer. Neither part overflows: the indices are clamped to 1e8,
    so the numerators and denominators stay below about 1e8.
    """
    return z.real * z.real + z.imag * z.imag


def fresnel_dielectric(cos_theta, eta_i, eta_t) -> np.ndarray:
    """
    Unpolarised Fresnel reflectance between two real indices in closed form.

    Parameters
    ----------
    cos_theta
        :math:`\\mu` in the incident medium, [0, 1].
    eta_i, eta_t
        Real indices of the incident and transmitting media, > 0.

    Returns
    -------
    numpy.ndarray
        Reflectance in [0, 1]; 1 under total internal reflection. Never NaN
        for finite input (indices clamped to :data:`fitting.domain.INDEX_LIMITS`,
        cos theta to [0, 1]); NaN in any input gives NaN.
    """
    lo, hi = INDEX_LIMITS
    mu = np.clip(as_float_array("cos_theta", cos_theta), 0.0, 1.0)
    eta_i = np.clip(as_float_array("eta_i", eta_i), lo, hi)
    eta_t = np.clip(as_float_array("eta_t", eta_t), lo, hi)
    sin2_t = (eta_i / eta_t) ** 2 * (1.0 - mu * mu)
    tir = sin2_t >= 1.0
    cos_t = np.sqrt(np.clip(1.0 - sin2_t, 0.0, 1.0))
    tiny = np.finfo(np.float64).tiny
    rs = (eta_i * mu - eta_t * cos_t) / np.maximum(eta_i * mu + eta_t * cos_t, tiny)
    rp = (eta_t * mu - eta_i * cos_t) / np.maximum(eta_t * mu + eta_i * cos_t, tiny)
    R = np.where(tir, 1.0, 0.5 * (rs * rs + rp * rp))
    # Equal indices: no interface, no reflection, even at grazing incidence.
    return np.clip(np.where(eta_i == eta_t, 0.0, R), 0.0, 1.0)
