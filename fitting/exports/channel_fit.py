"""
A base Fresnel fitted per channel
=================================

Per colour channel, the least-squares fit of one tool's base Fresnel to a
reflectance curve over the view angles: the start of the seen fit
(:mod:`fitting.exports.seen_fit`, which re-exports them) and the naive fits
under the coat.

-   :func:`fit_channel_conductor`: n + i k of an exact conductor in air
    (scipy's ``trf`` with the closed form's central differences; per channel,
    or the three channels in one call, their Jacobian block-diagonal: the
    same optimum to about 1e-9, in about 60 % of the time. The seen fits
    start from the per-channel solves; the naive fits are joint).
-   :func:`fit_channel_f82`: F0 and the F82 tint (exact Jacobian).
-   :func:`fit_channel_schlick`: Schlick's F0, closed form.
-   :func:`least_squares`: scipy's, imported on first use.
"""

from __future__ import annotations

import numpy as np

from ..optics.fresnel import fresnel_conductor
from .tool_fresnel import F82_COS_THETA, f82_tint, schlick
from .tool_layering import K_BOUNDS, N_BOUNDS

__all__ = ["fit_channel_conductor", "fit_channel_f82", "fit_channel_schlick", "least_squares"]

_TOL = dict(xtol=1e-12, ftol=1e-12, gtol=1e-12)


def least_squares(*args, **kwargs):
    """scipy's ``least_squares``, imported on first use: the export writers are imported by every
    ``python -m fitting`` command (the CLI's choices come from the format registry), most of which fit
    nothing here."""
    from scipy.optimize import least_squares as solve

    return solve(*args, **kwargs)


def _conductor_jacobian(mu: np.ndarray, x: np.ndarray) -> np.ndarray:
    """
    (S, 2) derivative of the conductor's Fresnel in n and k at ``x``:
    central differences (step 1e-6 max(1, |x|), one-sided at a bound) of
    the closed form, the four points in one call.
    """
    lo, hi = np.array([N_BOUNDS[0], K_BOUNDS[0]]), np.array([N_BOUNDS[1], K_BOUNDS[1]])
    h = 1e-6 * np.maximum(1.0, np.abs(x))
    up, down = np.minimum(x + h, hi), np.maximum(x - h, lo)
    n = np.array([up[0], down[0], x[0], x[0]])
    k = np.array([x[1], x[1], up[1], down[1]])
    R = fresnel_conductor(mu[:, None], 1.0, n, k)
    return np.stack([(R[:, 0] - R[:, 1]) / (up[0] - down[0]), (R[:, 2] - R[:, 3]) / (up[1] - down[1])], axis=1)


def _f82_jacobian(mu: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(S, 2) derivative of :func:`f82_tint` in F0 and the tint (bilinear in them), exact."""
    m = F82_COS_THETA
    w = (1.0 - mu) ** 5
    u = mu * (1.0 - mu) ** 6 / (m * (1.0 - m) ** 6)
    Sm = x[0] + (1.0 - x[0]) * (1.0 - m) ** 5
    return np.stack([1.0 - w - u * (1.0 - (1.0 - m) ** 5) * (1.0 - x[1]), u * Sm], axis=1)


def _per_channel(mu: np.ndarray, T: np.ndarray, model, jacobian, x0, lo, hi) -> np.ndarray:
    """
    The three channels' two unknowns each (``x0`` (3, 2), bounds ``lo``, ``hi`` (2,)) fitted as one
    least-squares problem of 6 unknowns: each channel's residuals depend on its own unknowns alone
    (a block-diagonal Jacobian), so the optimum is each channel's (to the tolerances), in one call
    instead of three.
    Returns (3, 2).
    """
    S = mu.size
    rows = np.arange(3 * S)
    col = np.repeat(np.arange(3), S)

    def residuals(x):
        x = x.reshape(3, 2)
        return (model(mu, x[:, 0], x[:, 1]) - T).T.ravel()  # model: (S, 3)

    def jac(x):
        x = x.reshape(3, 2)
        J = np.zeros((3 * S, 6))
        D = np.concatenate([jacobian(mu, x[c]) for c in range(3)])  # (3 S, 2)
        J[rows, 2 * col], J[rows, 2 * col + 1] = D[:, 0], D[:, 1]
        return J

    fit = least_squares(residuals, np.ravel(x0), jac=jac, bounds=(np.tile(lo, 3), np.tile(hi, 3)), method="trf", **_TOL)
    return fit.x.reshape(3, 2)


def fit_channel_conductor(mu: np.ndarray, T: np.ndarray, joint: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """
    Per channel, n + i k of an exact conductor in air whose Fresnel is nearest ``T`` (S, 3):
    one solve per channel, or with ``joint`` the three as one (:func:`_per_channel`).
    """
    lo, hi = [N_BOUNDS[0], K_BOUNDS[0]], [N_BOUNDS[1], K_BOUNDS[1]]
    if joint:
        F0 = np.clip(T[np.argmax(mu)], 0.0, 0.999)
        x0 = np.clip(np.stack([np.ones(3), np.sqrt(4.0 * F0 / (1.0 - F0))], axis=1), lo, hi)
        x = _per_channel(
            mu,
            T,
            lambda m, n, k: fresnel_conductor(m[:, None], 1.0, n, k),
            _conductor_jacobian,
            x0,
            np.asarray(lo),
            np.asarray(hi),
        )
        return x[:, 0].copy(), x[:, 1].copy()
    n_out, k_out = np.empty(3), np.empty(3)
    for c in range(3):
        R = T[:, c]
        # At normal incidence with n = 1, R = k^2 / (4 + k^2): a start from F0.
        F0 = float(np.clip(R[np.argmax(mu)], 0.0, 0.999))
        x0 = np.clip([1.0, np.sqrt(4.0 * F0 / (1.0 - F0))], lo, hi)
        fit = least_squares(
            lambda x: fresnel_conductor(mu, 1.0, x[0], x[1]) - R,
            x0,
            jac=lambda x: _conductor_jacobian(mu, x),
            bounds=(lo, hi),
            method="trf",
            **_TOL,
        )
        n_out[c], k_out[c] = fit.x
    return n_out, k_out


def fit_channel_f82(mu: np.ndarray, T: np.ndarray, joint: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Per channel, F0 and F82 tint in [0, 1] of the F82-tint model nearest ``T`` (``joint``: as
    :func:`fit_channel_conductor`)."""
    if joint:
        x0 = np.clip(np.stack([T[np.argmax(mu)], np.ones(3)], axis=1), 0.0, 1.0)
        x = _per_channel(mu, T, f82_tint, _f82_jacobian, x0, np.zeros(2), np.ones(2))
        return x[:, 0].copy(), x[:, 1].copy()
    F0, tint = np.empty(3), np.empty(3)
    for c in range(3):
        R = T[:, c]
        x0 = np.clip([R[np.argmax(mu)], 1.0], 0.0, 1.0)
        fit = least_squares(
            lambda x: f82_tint(mu, x[0], x[1]) - R,
            x0,
            jac=lambda x: _f82_jacobian(mu, x),
            bounds=([0.0, 0.0], [1.0, 1.0]),
            method="trf",
            **_TOL,
        )
        F0[c], tint[c] = fit.x
    return F0, tint


def fit_channel_schlick(mu: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Schlick's F0 nearest ``T`` in least squares, closed form, clipped to [0, 1]."""
    # Schlick is linear in F0: F - w = F0 (1 - w) with w = (1 - mu)^5.
    w = schlick(mu, 0.0)[:, None]
    F0 = np.sum((1.0 - w) * (T - w), axis=0) / np.sum((1.0 - w) ** 2)
    return np.clip(F0, 0.0, 1.0)
