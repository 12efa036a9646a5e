"""
Float16 quantisation
====================

-   :func:`quantise_coefficients`: float16 coefficients that minimise the
    fitted objective (a :class:`fitting.fits.objective.Problem`), not merely
    the rounded float64 fit.

References
----------
Frantar, E., et al. (2023). GPTQ: Accurate post-training quantization. ICLR
(sequential rounding with second-order error compensation).
"""

from __future__ import annotations

import numpy as np

from ..models.pack import FLOAT16_MAX, to_float16
from .objective import Problem

__all__ = ["quantise_coefficients", "compensations"]


def quantise_coefficients(problem: Problem, C: np.ndarray, passes: int = 3) -> np.ndarray:
    """
    Float16 coefficients that minimise the fit's objective near the float64
    optimum ``C``.

    With the Jacobian :math:`J` and residual :math:`r_0` at ``C``, the
    objective of a perturbation :math:`\\delta` is modelled as
    :math:`q(\\delta) = \\lVert r_0 + J\\delta \\rVert^2`. Coefficients are
    rounded one at a time, largest curvature first, each rounding compensated
    by re-solving the still-free coefficients (Frantar et al. 2023); then
    coordinate moves of one ulp that lower :math:`q` are taken. The result is
    kept only if the true objective beats nearest rounding.
    """
    x = C.ravel().astype(np.float64)
    r0 = problem.residuals(x)
    J = problem.jacobian(x)
    H = J.T @ J
    g = J.T @ r0
    n = x.size
    scale = np.sqrt(np.maximum(np.diag(H), 1e-300))
    Hs = H / np.outer(scale, scale) + 1e-12 * np.eye(n)

    # The compensations of every rounding at once (Frantar et al. 2023):
    # in the rounding order, row k of the upper Cholesky factor U of the
    # inverse (U^T U = Hs^-1) is, divided by U[k, k], the move of the
    # still-free coordinates that minimises q when coordinate k moves by one.
    # U is the inverse of V, V V^T = Hs with V upper: the Cholesky factor of
    # Hs with its order reversed (no explicit inverse of Hs).
    order = np.argsort(-np.diag(H))
    moves = compensations(Hs, order)
    u = np.zeros(n)  # the scaled change delta * scale, in the rounding order
    xs = x[order]
    for k, i in enumerate(order):
        target = float(np.float16(np.clip(xs[k] + u[k] / scale[i], -FLOAT16_MAX, FLOAT16_MAX)))
        step = (target - xs[k]) * scale[i] - u[k]
        if step != 0.0:
            u[k:] += step * moves[k, k:]
        u[k] = (target - xs[k]) * scale[i]
    delta = np.empty(n)
    delta[order] = u / scale[order]
    with np.errstate(over="ignore", invalid="ignore"):
        x16 = (x + delta).astype(np.float16)
    if not np.all(np.isfinite(x16)):
        # A near-singular compensation step left the float16 range: start
        # the coordinate moves from nearest rounding instead.
        x16 = to_float16(x)
    delta = x16.astype(np.float64) - x
    # One-ulp coordinate moves, best first. The change of q for a move s_i of
    # coordinate i alone is s_i (2 (H delta + g)_i + s_i H_ii): all moves are
    # scored at once, the best taken (the first of the lowest, ups before
    # downs), the gradient and the moved coordinate's steps updated, until
    # none helps.
    gradient = H @ delta + g
    curvature = np.diag(H)
    with np.errstate(over="ignore", invalid="ignore"):
        up, down = _ulp_steps(x16)
        for _ in range(passes * n):
            change_up = _finite_or_inf(up * (2.0 * gradient + up * curvature))
            change_down = _finite_or_inf(down * (2.0 * gradient + down * curvature))
            i_up, i_down = int(np.argmin(change_up)), int(np.argmin(change_down))
            if change_up[i_up] <= change_down[i_down]:
                i, step, best = i_up, up[i_up], change_up[i_up]
            else:
                i, step, best = i_down, down[i_down], change_down[i_down]
            if not best < 0.0:  # q strictly decreases: no cycles
                break
            x16[i] = np.float16(x16[i] + step)
            delta[i] += step
            gradient += H[:, i] * step
            up[i], down[i] = (v[0] for v in _ulp_steps(x16[i : i + 1]))
    x16 = (x + delta).astype(np.float16)
    nearest = to_float16(x)
    cost = np.sum(problem.residuals(x16.astype(np.float64)) ** 2)
    cost_nearest = np.sum(problem.residuals(nearest.astype(np.float64)) ** 2)
    chosen = x16 if cost <= cost_nearest else nearest
    return to_float16(chosen.astype(np.float64)).reshape(C.shape)


def compensations(Hs: np.ndarray, order: np.ndarray) -> np.ndarray:
    """
    Row k (in ``order``) is the move of coordinates ``order[k:]`` that
    minimises the quadratic form of the symmetric positive definite ``Hs``
    when coordinate ``order[k]`` moves by one and ``order[:k]`` are held:
    1 at k, :math:`-H_{FF}^{-1} H_{F i}` on the free F = ``order[k+1:]``.
    All rows from one factorisation: U = V^-1 with V V^T = Hs (in order, V
    upper: the Cholesky factor with the order reversed), each row of U
    divided by its diagonal (Frantar et al. 2023).
    """
    reversed_order = order[::-1]
    V = np.linalg.cholesky(Hs[np.ix_(reversed_order, reversed_order)])[::-1, ::-1]
    U = np.linalg.inv(V)
    return U / np.diag(U)[:, None]


def _ulp_steps(x16):
    """The steps (float64) to the next float16 up and down of each of ``x16``."""
    up = np.nextafter(x16, np.float16(np.inf)).astype(np.float64) - x16
    down = np.nextafter(x16, np.float16(-np.inf)).astype(np.float64) - x16
    return up, down


def _finite_or_inf(change):
    """``change`` with every non-finite value made +inf (never taken)."""
    change[~np.isfinite(change)] = np.inf
    return change
