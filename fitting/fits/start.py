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
    channel; the alpha with the smallest residual wins.
    """
    t = normalised_eta_i(eta, eta_i_range)
    T = np.stack([t**j for j in range(degree + 1)], axis=-1)
    x = 1.0 - np.clip(mu, 0.0, 1.0)
    x5 = x**5
    x0 = np.zeros((3, 3, degree + 1))
    best = np.full(3, np.inf)
    y = target - x5[:, None]
    for alpha in ALPHA_CANDIDATES:
        basis = np.concatenate([(1.0 - x5)[:, None] * T, -(mu * x**alpha)[:, None] * T], axis=1)
        coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
        res = ((basis @ coef - y) ** 2).sum(axis=0)
        for c in np.flatnonzero(res < best):
            best[c] = res[c]
            x0[0, c] = coef[: degree + 1, c]
            x0[1, c] = coef[degree + 1 :, c]
            x0[2, c] = 0.0
            x0[2, c, 0] = alpha
    return x0
