"""
The paper's method, fast
========================

The paper's own fit (Vernooij 2024, Section 4: plain linear-RGB least
squares of Eq. 1, float16 by rounding to nearest), the bar of the
worst-case guards (:mod:`fitting.fits.guarded`, :mod:`fitting.fits.curves_guard`):

-   :func:`paper_fit`: solved channel by channel (the channels of the model
    are independent), warm-started, with the joint solve
    (:func:`fitting.fits.solver.fit_coefficients`) as its fallback.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

import numpy as np

from ..models.coated_conductor import ALPHA_MIN, normalised_eta_i
from ..models.pack import to_float16
from ..numerics import trf_least_squares
from .objective import coefficient_bounds
from .result import FitResult
from .solver import fit_coefficients

__all__ = ["paper_fit"]


def _paper_channels(target, mu, eta, eta_i_range, start, max_nfev: int, boxed: bool = False):
    """
    Plain rgb least squares, channel by channel (the channels of the model
    are independent): the trust-region solve of the fits
    (:func:`fitting.numerics.trf_least_squares`) on the 3 (d + 1) unknowns
    of one channel at a time (Eq. 1 and its derivative written out for one
    channel), from ``start``; None when a channel does not converge or
    leaves the box. With ``boxed``, such a channel is solved again inside
    the box (:func:`_boxed`, from ``start`` clipped into it) instead.
    """
    C = np.array(start, dtype=np.float64)
    d1 = C.shape[2]
    lower, upper = (b.reshape(C.shape) for b in coefficient_bounds(d1 - 1))
    m = np.clip(np.ravel(mu), 0.0, 1.0)
    T = np.stack([normalised_eta_i(np.ravel(eta), eta_i_range) ** j for j in range(d1)], axis=-1)
    x = 1.0 - m
    x5 = x**5
    with np.errstate(divide="ignore"):
        log_x = np.where(x > 0.0, np.log(np.where(x > 0.0, x, 1.0)), 0.0)

    dF0 = (1.0 - x5)[:, None] * T
    last = [None, None]  # the solver asks for the Jacobian at the point it just evaluated

    def parts(xc):
        key = xc.tobytes()
        if key != last[0]:
            P = T @ xc.reshape(3, d1).T  # (S, 3): F0, a, alpha
            alpha = np.maximum(P[:, 2], ALPHA_MIN)
            last[:] = key, (P, alpha, m * np.where(x > 0.0, np.exp(alpha * log_x), 0.0))
        return last[1]

    for c in range(3):
        y = target[:, c]

        def residuals(xc, y=y):
            P, _, mu_xa = parts(xc)
            return P[:, 0] + (1.0 - P[:, 0]) * x5 - P[:, 1] * mu_xa - y

        def jacobian(xc):
            P, _, mu_xa = parts(xc)
            dalpha = np.where(P[:, 2] > ALPHA_MIN, -P[:, 1] * mu_xa * log_x, 0.0)
            J = np.empty((m.size, 3 * d1))
            J[:, :d1] = dF0  # the F0 columns do not depend on the coefficients
            np.multiply(-mu_xa[:, None], T, out=J[:, d1 : 2 * d1])
            np.multiply(dalpha[:, None], T, out=J[:, 2 * d1 :])
            return J

        x0 = C[:, c, :].ravel()
        fit = trf_least_squares(residuals, jacobian, x0, 1e-10, 1e-10, 1e-10, max_nfev)
        xc = fit.x.reshape(3, d1)
        if not fit.success or not np.all(np.isfinite(xc)) or np.any(xc < lower[:, c]) or np.any(xc > upper[:, c]):
            if not boxed:
                return None
            lo, hi = lower[:, c].ravel(), upper[:, c].ravel()
            inside = _boxed(residuals, jacobian, np.clip(x0, lo, hi), lo, hi, max_nfev)
            if inside is None:
                return None
            xc = inside.reshape(3, d1)
        C[:, c, :] = xc
    return C


def _boxed(residuals, jacobian, x0, lo, hi, max_nfev: int):
    """
    Least squares of ``residuals`` inside the box [``lo``, ``hi``] from
    ``x0`` (inside it) by an active set: the trust-region solve
    (:func:`fitting.numerics.trf_least_squares`) of the unknowns still
    free, each unknown that leaves the box held at the end it crossed, then
    the others solved again (at most once per unknown; no SVD of the tall
    Jacobian, as scipy's bounded solve does each step). None when a solve
    is not finite.
    """
    x, free = np.array(x0, dtype=np.float64), np.ones(np.size(x0), dtype=bool)
    while free.any():

        def at(v, x=x, free=free):
            y = x.copy()
            y[free] = v
            return y

        def free_residuals(v, at=at):
            return residuals(at(v))

        def free_jacobian(v, at=at, free=free):
            return jacobian(at(v))[:, free]

        fit = trf_least_squares(free_residuals, free_jacobian, x[free], 1e-10, 1e-10, 1e-10, max_nfev)
        if not np.all(np.isfinite(fit.x)):
            return None
        y = at(fit.x)
        out = (y < lo) | (y > hi)
        x = np.clip(y, lo, hi)
        if not out.any():
            break
        free = free & ~out
    return x


def paper_fit(
    target, mu, eta, eta_i_range, degree, max_nfev, mean_fit: FitResult, range_check=None, boxed: bool = False
) -> FitResult:
    """
    The paper's method on the guard points: plain rgb least squares,
    float16 by rounding to nearest (as the paper ships it). Warm-started
    from the mean fit and solved channel by channel (a fifth of the cost of
    the joint solve, the same optimum to 1e-5); the joint
    :func:`fitting.fits.solver.fit_coefficients` when that fails or a
    range constraint applies. ``boxed``: a channel that leaves the
    coefficients' box is solved inside it, channel by channel too
    (:func:`_paper_channels`).
    """
    C = (
        None
        if range_check is not None
        else _paper_channels(target, mu, eta, eta_i_range, mean_fit.coefficients, max_nfev, boxed)
    )
    if C is None:
        return fit_coefficients(
            target,
            mu,
            eta,
            eta_i_range,
            degree,
            "rgb",
            max_nfev,
            False,
            irls_rounds=0,
            range_check=range_check,
            start=mean_fit.coefficients,
        )
    return mean_fit.with_coefficients(C, to_float16(C))
