"""
The start of a fit
==================

-   :func:`initial_guess`: deterministic coefficients to start the solver
    from, by variable projection on a ladder of constant exponents.
"""

from __future__ import annotations

import numpy as np

from ..models.coated_conductor import normalised_eta_i

__all__ = ["ALPHA_CANDIDATES", "initial_guess"]


ALPHA_CANDIDATES = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0, 16.0, 24.0])


def initial_guess(target, mu, eta, eta_i_range, degree) -> np.ndarray:
    """
    Variable projection on a ladder of constant exponents: for each alpha the
    model is linear in the F0 and a polynomials, solved by least squares per
    channel (every rung's normal equations in one stacked solve; per rung by
    an SVD where they are singular); the alpha with the smallest residual
    wins (the first on a tie).
    """
    t = normalised_eta_i(eta, eta_i_range)
    d1 = degree + 1
    T = np.stack([t**j for j in range(d1)], axis=-1)
    x = 1.0 - np.clip(mu, 0.0, 1.0)
    x5 = x**5
    y = target - x5[:, None]
    basis = np.empty((ALPHA_CANDIDATES.size, mu.size, 2 * d1))  # [rung, sample, F0 then a]
    basis[:, :, :d1] = (1.0 - x5)[:, None] * T
    basis[:, :, d1:] = -(mu * x ** ALPHA_CANDIDATES[:, None])[:, :, None] * T
    transposed = basis.transpose(0, 2, 1)
    try:
        coef = np.linalg.solve(transposed @ basis, transposed @ y)  # (rungs, 2 d1, 3)
    except np.linalg.LinAlgError:
        coef = None
    if coef is None or not np.all(np.isfinite(coef)):  # samples that leave a rung's basis rank deficient
        coef = np.stack([np.linalg.lstsq(b, y, rcond=None)[0] for b in basis])
    residual = ((basis @ coef - y) ** 2).sum(axis=1)  # (rungs, 3)
    best = np.argmin(residual, axis=0)
    x0 = np.zeros((3, 3, d1))
    for c, rung in enumerate(best):
        x0[0, c] = coef[rung, :d1, c]
        x0[1, c] = coef[rung, d1:, c]
        x0[2, c, 0] = ALPHA_CANDIDATES[rung]
    return x0
