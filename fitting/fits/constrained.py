"""
The constrained refit of a guarded fit
======================================

One refit of least mean Delta E with the max capped, for
:mod:`fitting.fits.guarded` (which re-exports its public names):

-   :func:`constrained_mean`: SLSQP from a start, the first-order Delta E
    2000 at every guard point near the cap constrained under it (and the
    model kept in [0, 1] at the range points), the active set grown while
    the solution leaves points above the cap.
-   :class:`GuardWork`: the work the constrained refits of one guard may
    do, a deterministic bound on their CPU time.
"""

from __future__ import annotations

import numpy as np

from ..models.coated_conductor import coated_conductor_model, model_jacobian
from ..numerics import scipy_optimize
from .objective import Problem, coefficient_bounds, delta_E_gradients

__all__ = ["GuardWork", "constrained_mean"]

_SLSQP_ITERATIONS = 25  # SLSQP iterations of a constrained fit (27 unknowns)
_ACTIVE_ROUNDS = 3  # solves of a constrained fit as points above the cap join the constraints


class _Cached:
    """
    Residuals and Jacobian of a :class:`Problem`, each computed once per
    point (SLSQP asks for values and derivatives apart) and the Jacobian
    only where asked for: about two in three of the points SLSQP evaluates
    are line-search trials whose derivatives it never uses.
    """

    def __init__(self, problem: Problem) -> None:
        self.problem, self.key = problem, None
        self.r = self.J = self._jacobian = None  # at the point of `key`; J once asked for

    def _at(self, x) -> None:
        key = x.tobytes()
        if key != self.key:
            self.key, self.J = key, None
            self.r, self._jacobian = self.problem.residuals_deferred(x)

    def residuals(self, x):
        self._at(x)
        return self.r

    def jacobian(self, x):
        self._at(x)
        if self.J is None:
            self.J = self._jacobian()
        return self.J


class GuardWork:
    """
    The work a guard's constrained refits may do, in SLSQP iterations
    times the rows of their constraints (the QP of each iteration grows
    with its rows): a deterministic bound on their CPU time, the same on
    every machine. ``None`` where a guard has no bound (material fits).
    """

    def __init__(self, units: int) -> None:
        self.left = int(units)
        self.cut = False  # a refit was shortened or not started for the budget

    def iterations(self, rows: int, wanted: int) -> int:
        """SLSQP iterations of a solve with ``rows`` constraint rows (0: none left; marked cut when short)."""
        allowed = min(wanted, self.left // max(1, rows))
        if allowed < wanted:
            self.cut = True
        return allowed if allowed >= _MIN_ITERATIONS else 0

    def spend(self, rows: int, iterations: int) -> None:
        self.left -= rows * max(1, int(iterations))


_MIN_ITERATIONS = 5  # a budget-shortened SLSQP solve with fewer iterations is not started


def constrained_mean(
    mean_problem: Problem,
    guard_problem: Problem,
    weights,
    x0,
    cap: float,
    degree: int,
    max_iterations: int = _SLSQP_ITERATIONS,
    range_points=None,
    work: GuardWork | None = None,
):
    """
    Coefficients minimising the weighted mean of the first-order Delta E
    2000 over the fitting samples subject to Delta E <= ``cap`` at every
    guard point (as squares, which are smooth), by SLSQP from ``x0``; None
    when SLSQP fails to find a point inside the cap.

    The constraints are those of the guard points within half the cap of it
    at the start, and any point the solution leaves above the cap joins
    them for another solve (at most :data:`_ACTIVE_ROUNDS`): the max is
    where a few points are, and each constraint costs the QP of every step.
    ``range_points`` = (cos_theta, eta_i): points where the model must also
    stay in [0, 1] (the same active-set rule, per channel and end: a row
    for each channel within 0.05 of an end). ``work``: the
    :class:`GuardWork` left; None when it is spent.
    """
    S = mean_problem.mu.size
    w = np.ravel(weights) / np.sum(weights)
    lower, upper = coefficient_bounds(degree)
    x = np.clip(np.ravel(x0), lower, upper)
    gT, gM, gE = guard_problem.target, guard_problem.mu, guard_problem.eta

    def guard_dE(x):
        return np.linalg.norm(guard_problem.residuals(x).reshape(-1, 3), axis=1)

    active = guard_dE(x) > 0.5 * cap
    if range_points is not None:
        rM, rE = np.ravel(range_points[0]), np.ravel(range_points[1])

        def model_at(x):
            return coated_conductor_model(rM, rE, x.reshape(3, 3, degree + 1), mean_problem.range)

        F0 = model_at(x)
        near = np.stack([F0 < 0.05, F0 > 0.95], axis=-1)  # (K, 3, 2): point, channel, lower / upper end
    for _ in range(_ACTIVE_ROUNDS):
        both = _Cached(
            Problem(
                np.concatenate([mean_problem.target, gT[active]]),
                np.concatenate([mean_problem.mu, gM[active]]),
                np.concatenate([mean_problem.eta, gE[active]]),
                mean_problem.range,
                degree,
                "de2000",
                None,
                None,
            )
        )

        def objective(x):
            r = both.residuals(x)
            return float(w @ np.sqrt(np.sum(r[:S] ** 2, axis=1)))

        def gradient(x):
            return w @ delta_E_gradients(both.residuals(x)[:S], both.jacobian(x)[:S])

        def constraint(x):
            return cap * cap - np.sum(both.residuals(x)[S:] ** 2, axis=1)

        def constraint_jac(x):
            return -2.0 * np.einsum("so,son->sn", both.residuals(x)[S:], both.jacobian(x)[S:])

        constraints = [{"type": "ineq", "fun": constraint, "jac": constraint_jac}]
        rows = int(active.sum())
        if range_points is not None and near.any():
            constraints.append(_range_constraint(rM, rE, near, mean_problem.range, degree))
            rows += int(near.sum())
        iterations = max_iterations if work is None else work.iterations(rows, max_iterations)
        if iterations == 0:
            return None
        optimize, threadpools = scipy_optimize()  # the constrained refits alone import scipy.optimize
        with threadpools.limit(limits=1, user_api="blas"):
            result = optimize.minimize(
                objective,
                x,
                jac=gradient,
                method="SLSQP",
                bounds=list(zip(lower, upper)),
                constraints=constraints,
                options={"maxiter": iterations, "ftol": 1e-9},
            )
        if work is not None:
            work.spend(rows, result.nit)
        if not np.all(np.isfinite(result.x)):
            return None
        x = result.x
        over = guard_dE(x) > cap * (1.0 + 1e-6)
        grown = (over & ~active).any()
        active |= over
        if range_points is not None:
            F = model_at(x)
            leaving = np.stack([F < 0.0, F > 1.0], axis=-1)
            grown = grown or (leaving & ~near).any()
            near |= leaving
        if not grown:
            break
    if guard_dE(x).max() > cap * (1.0 + 1e-3):
        return None
    return x.reshape(3, 3, degree + 1)


def _range_constraint(mu, eta, rows, eta_i_range, degree: int, margin: float = 1e-5) -> dict:
    """
    SLSQP inequalities ``F >= margin`` and ``F <= 1 - margin`` at the
    points (``mu``, ``eta``), one row per True of ``rows`` (point,
    channel, lower / upper end), with their Jacobian.
    """
    points = rows.any(axis=(1, 2))
    mu, eta, rows = np.ravel(mu)[points], np.ravel(eta)[points], rows[points]
    k, c, end = np.nonzero(rows)
    sign = np.where(end == 0, 1.0, -1.0)
    offset = np.where(end == 0, -margin, 1.0 - margin)
    d1 = degree + 1

    def fun(x):
        F, _ = model_jacobian(mu, eta, x.reshape(3, 3, d1), eta_i_range)
        return sign * F[k, c] + offset

    def jac(x):
        _, Jm = model_jacobian(mu, eta, x.reshape(3, 3, d1), eta_i_range)  # (K, 3, 3, d1): channel c's
        J = np.zeros((k.size, 3, 3, d1))
        J[np.arange(k.size), :, c, :] = sign[:, None, None] * Jm[k, c]
        return J.reshape(k.size, -1)

    return {"type": "ineq", "fun": fun, "jac": jac}
