"""
Coated-conductor Fresnel model
==============================

The RGB model of Vernooij (2024), Eq. 1 and 2, defined once for numpy. The
GLSL version in ``preview_shaders/glsl/`` mirrors it term by term and the two
are tested against each other.

Per channel :math:`c \\in \\{R, G, B\\}`:

.. math::

    F(\\mu, \\eta_i) = F_0 + (1 - F_0)(1 - \\mu)^5 - a\\,\\mu(1 - \\mu)^{\\alpha}
    \\qquad \\text{(Eq. 1)}

with each of :math:`F_0, a, \\alpha` a polynomial of degree *d* <= 2 in the
normalised coating index :math:`t = (\\eta_i - lo)/(hi - lo)`, clamped to
[0, 1] (Eq. 2 uses :math:`\\eta_i` itself; *t* is better conditioned and
kinder to float16).

Coefficient layout: ``coefficients[p, c, j]`` with parameter *p* in
(F0, a, alpha), channel *c* in (R, G, B), power *j* in (1, t, t^2). This is
also the order of the 27 halves of the binary pack.

-   :func:`coated_conductor_model`: evaluates the model, linear ACEScg.
-   :func:`model_parameters`: F0, a, alpha per channel at given eta_i.
-   :func:`collapse_to_eta_i`: the scene-specialised 9 numbers at one eta_i.
-   :func:`model_jacobian`: derivative of the model in its coefficients.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
Lazanyi, I., & Szirmay-Kalos, L. (2005). Fresnel term approximations for metals. WSCG.
"""

from __future__ import annotations

import numpy as np

from ..domain import DEFAULT_ETA_I_RANGE, as_float_array

__all__ = [
    "PARAMETERS",
    "CHANNELS",
    "ALPHA_MIN",
    "lean_constants",
    "normalised_eta_i",
    "check_coefficients",
    "model_parameters",
    "collapse_to_eta_i",
    "coated_conductor_model",
    "ModelAt",
    "model_from_parameters",
    "model_jacobian",
]

PARAMETERS = ("F0", "a", "alpha")
CHANNELS = ("R", "G", "B")

PARAMETER_LIMIT = 1.0e6
"""Where F0, a and alpha are clamped (magnitude). A float16 pack cannot reach
it (each parameter is at most 3 x 65504 in magnitude), so packs are never
affected; the clamp keeps the sum of Eq. 1 finite for any finite
coefficients (inf - inf would be NaN)."""

ALPHA_MIN = 1.0e-3
"""Lower clamp of the exponent alpha: keeps (1 - mu)^alpha finite at mu = 1
for any coefficients (a non-positive exponent would give 0^0 or 1/0)."""


def check_coefficients(coefficients) -> np.ndarray:
    """
    Validate a coefficient array of shape (3, 3, d + 1), d in {0, 1, 2}.

    Raises
    ------
    ValueError
        If the shape is wrong or a value is not finite.
    """
    C = np.asarray(coefficients, dtype=np.float64)
    if C.ndim != 3 or C.shape[:2] != (3, 3) or not 1 <= C.shape[2] <= 3:
        raise ValueError(
            "`coefficients` must have shape (3, 3, d + 1) with d in {0, 1, 2} "
            f"(parameter F0/a/alpha, channel R/G/B, power), got {C.shape}"
        )
    if not np.all(np.isfinite(C)):
        raise ValueError("`coefficients` must be finite")
    return C


def normalised_eta_i(eta_i, eta_i_range=DEFAULT_ETA_I_RANGE) -> np.ndarray:
    """
    :math:`t = (\\eta_i - lo)/(hi - lo)` clamped to [0, 1]; 0 when lo = hi.
    """
    lo, hi = eta_i_range
    eta_i = np.asarray(eta_i, dtype=np.float64)
    if hi <= lo:
        return np.zeros_like(eta_i)
    return np.clip((eta_i - lo) / (hi - lo), 0.0, 1.0)


def _powers(t: np.ndarray, degree: int) -> np.ndarray:
    """(..., degree + 1) array of 1, t, t^2."""
    return np.stack([t**j for j in range(degree + 1)], axis=-1)


def model_parameters(coefficients, eta_i, eta_i_range=DEFAULT_ETA_I_RANGE) -> np.ndarray:
    """
    F0, a and alpha per channel at ``eta_i``.

    Returns
    -------
    numpy.ndarray
        Shape ``eta_i.shape + (3, 3)``: [..., parameter, channel]; alpha is
        clamped to :data:`ALPHA_MIN`.
    """
    C = np.asarray(coefficients, dtype=np.float64)
    t = normalised_eta_i(eta_i, eta_i_range)
    return _parameters(_powers(t, C.shape[2] - 1), C)


def _parameters(T, C) -> np.ndarray:
    """:func:`model_parameters` from the powers of t ``T`` (..., d + 1) and the coefficients ``C``."""
    with np.errstate(over="ignore", invalid="ignore"):
        P = np.einsum("...j,pcj->...pc", T, C)
    # Clamped, not refused (see PARAMETER_LIMIT); np.clip keeps NaN.
    P = np.clip(P, -PARAMETER_LIMIT, PARAMETER_LIMIT)
    P[..., 2, :] = np.maximum(P[..., 2, :], ALPHA_MIN)
    return P


def collapse_to_eta_i(coefficients, eta_i, eta_i_range=DEFAULT_ETA_I_RANGE) -> np.ndarray:
    """
    The scene-specialised model at one constant ``eta_i``: a (3, 3, 1) array
    of F0, a, alpha per channel (the quadratics evaluated on the CPU).
    """
    C = check_coefficients(coefficients)
    P = model_parameters(C, float(eta_i), eta_i_range)
    return P[..., None]


def lean_constants(coefficients, eta_i_range=DEFAULT_ETA_I_RANGE) -> tuple[np.ndarray, tuple[float, float]]:
    """
    The per-material constants of the lean general shader
    (``cf_coated_conductor_lean``): a (3, 3, 3) array P[p, j, c], parameter p,
    power j of t, channel c (the coefficients with channel and power
    swapped, degree padded to 2), and ``t_map`` (s, o) with
    t = clamp(eta_i s + o, 0, 1) equal to :func:`normalised_eta_i`
    ((0, 0) for a single-index fit).
    """
    C = check_coefficients(coefficients)
    P = np.zeros((3, 3, 3))
    P[:, : C.shape[2], :] = np.swapaxes(C, 1, 2)
    lo, hi = (float(v) for v in eta_i_range)
    t_map = (1.0 / (hi - lo), -lo / (hi - lo)) if hi > lo else (0.0, 0.0)
    return P, t_map


def model_from_parameters(cos_theta, F0, a, alpha) -> np.ndarray:
    """
    Eq. 1 from per-channel parameters broadcast against ``cos_theta``:
    :math:`F_0 + (1 - F_0)(1 - \\mu)^5 - a\\mu(1 - \\mu)^{\\alpha}`.
    """
    mu = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)
    x = 1.0 - mu
    x5 = x**5
    return F0 + (1.0 - F0) * x5 - a * mu * x ** np.maximum(alpha, ALPHA_MIN)


def coated_conductor_model(cos_theta, eta_i, coefficients, eta_i_range=DEFAULT_ETA_I_RANGE) -> np.ndarray:
    """
    Evaluate the coated-conductor model (Vernooij 2024, Eq. 1 and 2).

    Parameters
    ----------
    cos_theta
        :math:`\\mu = \\cos\\theta` in the coating, [0, 1] (clamped).
    eta_i
        Index of the coating, broadcast against ``cos_theta``; clamped to
        ``eta_i_range``.
    coefficients
        (3, 3, d + 1) array, see the module docstring for the layout.
    eta_i_range
        The fitted domain [lo, hi] of eta_i.

    Returns
    -------
    numpy.ndarray
        Reflectance in linear ACEScg, shape ``broadcast(cos_theta, eta_i) + (3,)``.

    Never raises on numeric input and never returns NaN for finite input:
    cos theta is clamped to [0, 1], eta_i to the domain, the parameters to
    +/- :data:`PARAMETER_LIMIT` and alpha to at least :data:`ALPHA_MIN`. A
    NaN in ``cos_theta`` or ``eta_i`` gives NaN at its position (the API,
    the CLI and the curve readers refuse NaN before it gets here).

    Raises
    ------
    ValueError
        If ``cos_theta`` or ``eta_i`` is not numbers.
    """
    return ModelAt(cos_theta, eta_i, eta_i_range)(coefficients)


class ModelAt:
    """
    :func:`coated_conductor_model` at fixed (``cos_theta``, ``eta_i``) for
    many coefficient arrays: what the samples fix (the powers of *t*,
    :math:`1 - \\mu`, :math:`(1 - \\mu)^5`) computed once, for solvers that
    evaluate one set of samples hundreds of times. Calling it with
    ``coefficients`` is :func:`coated_conductor_model` (which is defined by
    it), the same operations on the same values.
    """

    def __init__(self, cos_theta, eta_i, eta_i_range=DEFAULT_ETA_I_RANGE) -> None:
        mu, eta_i = np.broadcast_arrays(as_float_array("cos_theta", cos_theta), as_float_array("eta_i", eta_i))
        self.t = normalised_eta_i(eta_i, eta_i_range)
        self.powers: dict[int, np.ndarray] = {}
        self.mu = np.clip(mu[..., None], 0.0, 1.0)
        self.x = 1.0 - self.mu
        self.x5 = self.x**5

    def powers_of(self, d1: int) -> np.ndarray:
        """The powers 1, t, ..., t^(d1 - 1) at the samples, shape (..., d1), computed once per ``d1``."""
        if d1 not in self.powers:
            self.powers[d1] = _powers(self.t, d1 - 1)
        return self.powers[d1]

    def __call__(self, coefficients) -> np.ndarray:
        C = np.asarray(coefficients, dtype=np.float64)
        P = _parameters(self.powers_of(C.shape[2]), C)
        F0, a, alpha = P[..., 0, :], P[..., 1, :], P[..., 2, :]
        return F0 + (1.0 - F0) * self.x5 - a * self.mu * self.x ** np.maximum(alpha, ALPHA_MIN)


def model_jacobian(cos_theta, eta_i, coefficients, eta_i_range=DEFAULT_ETA_I_RANGE):
    """
    Model values and their derivative in the coefficients.

    Returns
    -------
    tuple
        ``F`` of shape (S, 3) and ``J`` of shape (S, 3, 3, d + 1) with
        ``J[s, c, p, j] = dF[s, c] / d coefficients[p, c, j]`` (a channel
        depends only on its own coefficients), for S flattened samples.
    """
    C = np.asarray(coefficients, dtype=np.float64)
    mu = np.clip(np.ravel(np.asarray(cos_theta, dtype=np.float64)), 0.0, 1.0)
    t = np.ravel(normalised_eta_i(eta_i, eta_i_range))
    T = _powers(t, C.shape[2] - 1)  # (S, d+1)
    P = np.einsum("sj,pcj->spc", T, C)
    alpha_raw = P[:, 2, :]
    alpha = np.maximum(alpha_raw, ALPHA_MIN)
    F0, a = P[:, 0, :], P[:, 1, :]
    x = (1.0 - mu)[:, None]
    x5 = x**5
    x_alpha = x**alpha
    mu_x_alpha = mu[:, None] * x_alpha
    F = F0 + (1.0 - F0) * x5 - a * mu_x_alpha
    with np.errstate(divide="ignore", invalid="ignore"):
        log_x = np.where(x > 0.0, np.log(np.where(x > 0.0, x, 1.0)), 0.0)
    dF0 = np.broadcast_to(1.0 - x5, F.shape)
    da = -mu_x_alpha
    dalpha = np.where(alpha_raw > ALPHA_MIN, -a * mu_x_alpha * log_x, 0.0)
    dP = np.stack([dF0, da, dalpha], axis=-1)  # (S, c, p)
    J = dP[..., None] * T[:, None, None, :]
    return F, J
