"""
A trust-region least-squares solver for small problems
======================================================

-   :func:`trf_least_squares`: :math:`\\min_x \\tfrac12 \\lVert f(x) \\rVert^2`
    by the trust-region method of :func:`scipy.optimize.least_squares`
    (``method="trf"`` without bounds, ``x_scale="jac"``, the exact
    subproblem), the same iteration, radius rule and stopping tests, with
    each subproblem solved by Cholesky factorisations of the scaled normal
    matrix (More 1977) instead of an SVD of the Jacobian.
-   :class:`TRFResult`: its result, the fields of scipy's that the fits read.

For the fits of this package (9 to 27 unknowns, about a hundred residuals)
scipy's SVD of the Jacobian and its per-call wrapping cost more than the
model itself; a 27 x 27 Cholesky factorisation costs a few microseconds.
Bounds are not handled here: without them the trust-region reflective
method is this trust-region method, and a fit whose optimum leaves its box
solves again with scipy's bounded ``trf``.

References
----------
More, J. J. (1977). The Levenberg-Marquardt algorithm: implementation and
theory. Numerical Analysis, Lecture Notes in Mathematics 630, 105-116.
Branch, M. A., Coleman, T. F., & Li, Y. (1999). A subspace, interior, and
conjugate gradient method for large-scale bound-constrained minimization
problems. SIAM J. Sci. Comput., 21(1), 1-23 (trust-region reflective).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["TRFResult", "trf_least_squares"]

_EPS = np.finfo(float).eps

MESSAGES = {
    -1: "The Jacobian is not finite at the current point.",
    0: "The maximum number of function evaluations is exceeded.",
    1: "`gtol` termination condition is satisfied.",
    2: "`ftol` termination condition is satisfied.",
    3: "`xtol` termination condition is satisfied.",
    4: "Both `ftol` and `xtol` termination conditions are satisfied.",
}
"""Status to message, as :func:`scipy.optimize.least_squares` words them."""


@dataclass
class TRFResult:
    """
    The result of :func:`trf_least_squares`: ``x`` (n,), ``cost``
    :math:`\\tfrac12 \\lVert f(x) \\rVert^2`, ``fun`` f(x) (m,), ``grad``
    :math:`J^T f` (n,), ``optimality`` its max norm, ``nfev`` / ``njev``
    the evaluations of f and J, ``status`` (-1: a Jacobian not finite, 0:
    out of evaluations, 1-4: the gtol, ftol, xtol, ftol-and-xtol tests),
    ``success`` (status > 0) and ``message``.
    """

    x: np.ndarray
    cost: float
    fun: np.ndarray
    grad: np.ndarray
    optimality: float
    nfev: int
    njev: int
    status: int

    @property
    def success(self) -> bool:
        return self.status > 0

    @property
    def message(self) -> str:
        return MESSAGES[self.status]


def _norm(v) -> float:
    """The 2-norm of a vector (np.linalg.norm's checks cost more than the sum here)."""
    return math.sqrt(np.dot(v, v))


def _inverse_factor(A):
    """
    ``(pivots, M)`` with M = L^-1 for the lower Cholesky factor L of the
    symmetric ``A`` (so A^-1 = M^T M) and its pivots diag(L), or None when
    ``A`` is not positive definite (numpy alone: scipy.linalg costs more
    to import than a fit).
    """
    try:
        L = np.linalg.cholesky(A)
    except np.linalg.LinAlgError:
        return None
    return L.diagonal(), np.linalg.inv(L)


def _gauss_newton(A, g, scale_inv):
    """
    The Gauss-Newton step -A^-1 g (in the unknowns) from the normal matrix
    ``A`` = J^T J and gradient ``g`` = J^T f, or None when J is not of full
    rank: scipy's test (smallest singular value of J over the largest)
    read from the Cholesky pivots of the scaled normal matrix, H positive
    definite with its pivots within 1e-7 of each other, so that the solve
    is accurate. One factorisation and one solve, without forming the
    scaled matrix: its pivots are A's over ``scale_inv``.
    """
    try:
        pivots = np.linalg.cholesky(A).diagonal() / scale_inv
    except np.linalg.LinAlgError:
        return None
    if pivots.min() <= 1e-7 * pivots.max():
        return None
    return -np.linalg.solve(A, g)


def _step(H, g, Delta, alpha, p_gn, rtol=0.01, max_iter=10):
    """
    The trust-region step of scipy's ``solve_lsq_trust_region`` from the
    normal matrix ``H`` = J^T J and gradient ``g`` = J^T f (scaled), where
    the Gauss-Newton step ``p_gn`` (scaled; None when J is not of full
    rank) is longer than ``Delta``:
    :math:`p = -(H + \\alpha I)^{-1} g` with :math:`\\lVert p \\rVert
    \\approx \\Delta` by Newton's method on :math:`\\phi(\\alpha) =
    \\lVert p \\rVert - \\Delta`, where :math:`\\phi' = -\\lVert L^{-1}
    p\\rVert^2 / \\lVert p \\rVert` (L L^T = H + alpha I; scipy's
    phi and phi' from the SVD, the same numbers). Returns ``(p, alpha)``.
    """
    eye = np.eye(g.size)
    full_rank = p_gn is not None
    factor = _inverse_factor(H) if full_rank else None
    if factor is not None:
        p_norm = _norm(p_gn)
        q = factor[1] @ p_gn
        alpha_lower = (p_norm - Delta) * p_norm / np.dot(q, q)
    else:
        alpha_lower = 0.0
    alpha_upper = _norm(g) / Delta
    if alpha is None or (not full_rank and alpha == 0):
        alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
    for _ in range(max_iter):
        if alpha < alpha_lower or alpha > alpha_upper:
            alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
        factor = _inverse_factor(H + alpha * eye)
        if factor is None:  # alpha at the rounding of H's smallest eigenvalue
            alpha_lower = alpha = max(alpha * 10.0, _EPS * np.trace(H), _EPS)
            continue
        M = factor[1]
        p = -M.T @ (M @ g)
        p_norm = _norm(p)
        phi = p_norm - Delta
        q = M @ p
        phi_prime = -np.dot(q, q) / p_norm
        if phi < 0:
            alpha_upper = alpha
        ratio = phi / phi_prime
        alpha_lower = max(alpha_lower, alpha - ratio)
        alpha -= (phi + Delta) * ratio / Delta
        if abs(phi) < rtol * Delta:
            break
    factor = _inverse_factor(H + alpha * eye)
    while factor is None:  # H is finite (checked by the caller): a large enough alpha makes it definite
        alpha = max(alpha * 10.0, _EPS * np.trace(H), _EPS)
        factor = _inverse_factor(H + alpha * eye)
    M = factor[1]
    p = -M.T @ (M @ g)
    return p * (Delta / _norm(p)), alpha


def _judge(actual_reduction, predicted_reduction, cost, Delta, step_h_norm, xtol_ok, ftol):
    """
    scipy's radius update and stopping tests after a trial step:
    ``(Delta_new, status)``, status None to go on, 2-4 for the ftol, xtol
    and both tests (``xtol_ok``: the step under ``xtol (xtol + |x|)``).
    """
    if predicted_reduction > 0:
        ratio = actual_reduction / predicted_reduction
    elif predicted_reduction == actual_reduction == 0:
        ratio = 1.0
    else:
        ratio = 0.0
    Delta_new = Delta
    if ratio < 0.25:
        Delta_new = 0.25 * step_h_norm
    elif ratio > 0.75 and step_h_norm > 0.95 * Delta:
        Delta_new = 2.0 * Delta
    ftol_ok = actual_reduction < ftol * cost and ratio > 0.25
    if ftol_ok or xtol_ok:
        return Delta_new, 4 if ftol_ok and xtol_ok else (2 if ftol_ok else 3)
    return Delta_new, None


def _trial_step(A, g, scale_inv, p_gn, Delta, alpha, H):
    """
    The trial step in the unknowns from the normal matrix ``A``, gradient
    ``g``, scales ``scale_inv`` and Gauss-Newton step ``p_gn`` (None when J
    is not of full rank): ``(step, its scaled norm, alpha, predicted
    reduction, H)``, H the scaled normal matrix once formed (None while
    only the Gauss-Newton step was needed).
    """
    if p_gn is not None:
        p_h_norm = _norm(p_gn * scale_inv)
        if p_h_norm <= Delta:
            return p_gn, p_h_norm, 0.0, -0.5 * np.dot(g, p_gn), H  # -(p^T A p / 2 + g^T p) with A p = -g
    d = 1.0 / scale_inv
    if H is None:
        H = A * d * d[:, None]
    g_h = d * g
    step_h, alpha = _step(H, g_h, Delta, alpha, None if p_gn is None else p_gn * scale_inv)
    return d * step_h, _norm(step_h), alpha, -(0.5 * step_h @ H @ step_h + g_h @ step_h), H


def trf_least_squares(
    fun: Callable[[np.ndarray], np.ndarray],
    jac: Callable[[np.ndarray], np.ndarray],
    x0,
    ftol: float = 1e-8,
    xtol: float = 1e-8,
    gtol: float = 1e-8,
    max_nfev: int = 100,
) -> TRFResult:
    """
    Minimise :math:`F(x) = \\tfrac12 \\lVert f(x) \\rVert^2`, f: R^n -> R^m,
    from ``x0`` by the trust-region method of scipy's ``least_squares``
    (``method="trf"``, no bounds, ``x_scale="jac"``, ``tr_solver="exact"``).

    Each iteration scales the unknowns by the running maximum of the
    Jacobian's column norms, takes the step minimising the linear model
    :math:`\\lVert f + J p \\rVert` in the trust region (:func:`_step`),
    and accepts it when F decreases; the radius is quartered when the
    actual reduction is under a quarter of the predicted one and doubled
    when it is over three quarters at the boundary.

    Parameters
    ----------
    fun
        f(x) -> (m,) residuals.
    jac
        J(x) -> (m, n), called at accepted points right after ``fun`` there.
    x0
        (n,) start.
    ftol, xtol, gtol
        Stop when a step's decrease of F is under ``ftol F`` (with a ratio
        of actual to predicted above 0.25), the step under ``xtol (xtol +
        |x|)``, or :math:`\\lVert J^T f \\rVert_\\infty` under ``gtol``.
    max_nfev
        Evaluations of f at most (the start included).

    Returns
    -------
    TRFResult
        Never raises for non-convergence: ``status`` 0 when ``max_nfev``
        was reached, -1 when J (at the start or an accepted point) is not
        finite; f not finite at a trial point shrinks the region instead.
    """
    x = np.array(x0, dtype=np.float64)
    f = np.asarray(fun(x), dtype=np.float64)
    J = np.asarray(jac(x), dtype=np.float64)
    nfev = njev = 1
    cost = 0.5 * np.dot(f, f)
    A, g = J.T @ J, J.T @ f
    scale_inv = np.sqrt(A.diagonal())
    scale_inv[scale_inv == 0] = 1.0
    Delta = _norm(x * scale_inv) or 1.0
    alpha = 0.0
    status = None
    while True:
        if not math.isfinite(A.sum() + g.sum()):  # one sum: a NaN or inf anywhere shows in it
            status = -1  # no step can be taken from a Jacobian that is not finite
            break
        if np.abs(g).max() < gtol:
            status = 1
        if status is not None or nfev == max_nfev:
            break
        # The Gauss-Newton step once per Jacobian (most steps of these fits
        # are that step); the scaled matrix and the search for alpha only
        # when it is longer than the region.
        p_gn = _gauss_newton(A, g, scale_inv) if J.shape[0] >= J.shape[1] else None
        H, x_norm = None, _norm(x)
        actual_reduction = -1.0
        while actual_reduction <= 0 and nfev < max_nfev:
            step, step_h_norm, alpha, predicted_reduction, H = _trial_step(A, g, scale_inv, p_gn, Delta, alpha, H)
            x_new = x + step
            f_new = np.asarray(fun(x_new), dtype=np.float64)
            nfev += 1
            cost_new = 0.5 * np.dot(f_new, f_new)
            if not math.isfinite(cost_new):  # f not finite there (or beyond 1e154): a smaller region
                Delta = 0.25 * step_h_norm
                continue
            actual_reduction = cost - cost_new
            Delta_new, status = _judge(
                actual_reduction,
                predicted_reduction,
                cost,
                Delta,
                step_h_norm,
                _norm(step) < xtol * (xtol + x_norm),
                ftol,
            )
            if status is not None:
                break
            alpha *= Delta / Delta_new
            Delta = Delta_new
        if actual_reduction > 0:
            x, f, cost = x_new, f_new, cost_new
            J = np.asarray(jac(x), dtype=np.float64)
            njev += 1
            A, g = J.T @ J, J.T @ f
            scale_inv = np.maximum(np.sqrt(A.diagonal()), scale_inv)
    return TRFResult(
        x=x,
        cost=float(cost),
        fun=f,
        grad=g,
        optimality=float(np.max(np.abs(g))),
        nfev=nfev,
        njev=njev,
        status=0 if status is None else status,
    )
