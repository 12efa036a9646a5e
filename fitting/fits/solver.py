"""
The solver
==========

Least-squares fit of the coated-conductor model
(:mod:`fitting.models.coated_conductor`) to reflectance samples, and the
float16 coefficients actually shipped.

-   :func:`fit_coefficients`: the model fitted to RGB samples at
    (cos theta, eta_i); the core shared by material, curve and scene fits.
-   :func:`solve`: one trust-region solve of a :class:`fitting.fits.objective.Problem`.
-   :func:`reweighted`: the rounds of iteratively reweighted least squares
    that turn a sum of squared Delta E into their mean (every kind's fit).

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
Branch, M. A., Coleman, T. F., & Li, Y. (1999). A subspace, interior, and
conjugate gradient method for large-scale bound-constrained minimization
problems. SIAM J. Sci. Comput., 21(1), 1-23 (trust-region reflective).
"""

from __future__ import annotations

import functools
import time

import numpy as np
from threadpoolctl import ThreadpoolController

from ..domain import DEFAULT_ETA_I_RANGE, check_choice, check_eta_i_range
from ..models.pack import to_float16
from ..numerics import scipy_optimize, trf_least_squares
from .objective import Problem, coefficient_bounds
from .quantise import quantise_coefficients
from .result import FitResult
from .settings import DEFAULT_OBJECTIVE, OBJECTIVES, check_degree
from .start import initial_guess

__all__ = ["fit_coefficients", "solve", "check_samples", "reweighted", "IRLS_FLOOR"]

# The fit's matrices are tiny (hundreds x 27): BLAS threads only add
# synchronisation cost, and oversubscribe the pool's worker processes.
_THREADPOOLS = ThreadpoolController()

IRLS_FLOOR = 0.02
"""Delta E below which samples stop gaining weight in :func:`reweighted`."""


def reweighted(problem, result, rounds: int, delta_E, base, resolve):
    """
    ``rounds`` rounds of iteratively reweighted least squares from
    ``result``, the optimum of ``problem``: each round weights sample *s* by
    ``base_s / max(dE_s, floor)`` with ``dE = delta_E(problem, x)`` and
    ``floor = max(IRLS_FLOOR, 1e-3 max dE)``, so that the weighted sum of
    squares approaches the sum of Delta E (its mean), and ``resolve(weights,
    x) -> (problem, result)`` solves again from ``x``.

    Returns
    -------
    tuple
        ``(problem, result, nfev, njev)``: the last problem and solve, and the
        evaluations of every solve from ``result`` on.
    """
    nfev, njev = result.nfev, result.njev or 0
    for _ in range(rounds):
        dE = delta_E(problem, result.x)
        floor = max(IRLS_FLOOR, 1e-3 * float(dE.max()))
        problem, result = resolve(base / np.maximum(dE, floor), result.x)
        nfev, njev = nfev + result.nfev, njev + (result.njev or 0)
    return problem, result, nfev, njev


def solve(problem: Problem, x0: np.ndarray, bounds, tol: float, max_nfev: int):
    """
    TRF from ``x0``, unbounded first (:func:`fitting.numerics.trf_least_squares`:
    scipy's iteration without its SVD, the analytic Jacobian); scipy's
    bounded solve is run only when the unbounded optimum leaves the box,
    i.e. when the data leave some coefficient unidentified.
    """
    lower, upper = bounds
    result = trf_least_squares(problem.residuals, problem.jacobian, x0, tol, tol, tol, max_nfev)
    if np.all(np.isfinite(result.x)) and np.all((result.x >= lower) & (result.x <= upper)):
        return result
    optimize, threadpools = scipy_optimize()  # the rare bounded solve only
    with threadpools.limit(limits=1, user_api="blas"):
        bounded = optimize.least_squares(
            problem.residuals,
            x0,
            bounds=(lower, upper),
            jac=problem.jacobian,
            method="trf",
            x_scale="jac",
            ftol=tol,
            xtol=tol,
            gtol=tol,
            max_nfev=max_nfev,
        )
    bounded.nfev += result.nfev
    bounded.njev = (bounded.njev or 0) + (result.njev or 0)
    return bounded


def _single_threaded_blas(function):
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with _THREADPOOLS.limit(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return wrapper


def check_samples(target_RGB, cos_theta, eta_i, weights=None):
    """
    The fitted samples as float64 arrays ``(target (S, 3), mu (S,), eta (S,),
    weights (S,) or None)``, every one finite and of one size, weights >= 0
    (the sample checks of every fit of RGB samples).
    """
    target = np.asarray(target_RGB, dtype=np.float64).reshape(-1, 3)
    mu = np.ravel(np.asarray(cos_theta, dtype=np.float64))
    eta = np.ravel(np.asarray(eta_i, dtype=np.float64))
    if not (mu.size == eta.size == target.shape[0]):
        raise ValueError("`target_RGB`, `cos_theta` and `eta_i` must have the same number of samples")
    for name, values in (("target_RGB", target), ("cos_theta", mu), ("eta_i", eta)):
        if not np.all(np.isfinite(values)):
            raise ValueError(f"`{name}` must be finite")
    if weights is not None:
        weights = np.ravel(np.asarray(weights, dtype=np.float64))
        if weights.size != mu.size or np.any(weights < 0) or not np.all(np.isfinite(weights)):
            raise ValueError("`weights` must be one finite value >= 0 per sample")
    return target, mu, eta, weights


@_single_threaded_blas
def fit_coefficients(
    target_RGB,
    cos_theta,
    eta_i,
    eta_i_range=DEFAULT_ETA_I_RANGE,
    degree: int = 2,
    objective: str = DEFAULT_OBJECTIVE,
    max_nfev: int = 200,
    quantise: bool = True,
    weights=None,
    irls_rounds: int = 2,
    range_check=None,
    start=None,
) -> FitResult:
    """
    Fit the coated-conductor model to linear ACEScg samples.

    Solves, with the trust-region reflective method and an analytic Jacobian,

    .. math::

        \\min_{C} \\tfrac12 \\sum_{s} w_s \\lVert r_s(C) \\rVert^2, \\qquad
        r_s = \\begin{cases}
            M(\\mu_s, \\eta_s; C) - T_s & \\text{rgb}\\\\
            Lab(M) - Lab(T_s) & \\text{lab}\\\\
            A_s\\,(Lab(M) - Lab(T_s)) & \\text{de2000}
        \\end{cases}

    over the coefficients :math:`C \\in \\mathbb{R}^{3 \\times 3 \\times (d+1)}`
    subject to the box :math:`|C_{F_0}| \\le 16`, :math:`|C_a| \\le 64`,
    :math:`|C_\\alpha| \\le 256` with :math:`C_{\\alpha,0} \\ge` ``ALPHA_MIN``
    (inactive for every measured conductor: the unbounded problem is solved
    first, the bounded one only when its optimum leaves the box, e.g. an
    alpha the data cannot identify), with :math:`M` the model of
    :mod:`fitting.models.coated_conductor`, :math:`T_s` the target, and :math:`A_s` the
    first-order CIEDE2000 metric at the target colour, so that
    :math:`\\lVert r_s \\rVert \\approx \\Delta E_{00}`. For ``de2000``,
    ``irls_rounds`` rounds then reweight :math:`w_s` by
    :math:`1/\\max(\\Delta E_s, 0.02)` so that the optimum approaches the mean
    Delta E. The start is a variable-projection solve over constant exponents,
    so the result is deterministic. Stopping: ``ftol = xtol = gtol = 1e-10``
    (1e-8 in the reweighting rounds) or ``max_nfev`` evaluations per solve.
    The float16 coefficients then minimise the same objective over the
    float16 lattice (:func:`quantise_coefficients`).

    Parameters
    ----------
    target_RGB
        (S, 3) linear ACEScg reflectance in [0, 1].
    cos_theta, eta_i
        (S,) sample positions: :math:`\\mu` in [0, 1], eta_i in the domain.
    eta_i_range
        Domain [lo, hi] of eta_i, 1 <= lo <= hi <= 3.
    degree
        Polynomial degree in t, 0-2; 0 when lo = hi.
    objective
        One of :data:`OBJECTIVES`.
    max_nfev
        Evaluation budget.
    quantise
        Choose the float16 coefficients by :func:`quantise_coefficients`;
        otherwise round to nearest.
    weights
        Optional (S,) non-negative sample weights :math:`w_s`.
    irls_rounds
        For ``de2000``: rounds of reweighting by :math:`1/\\Delta E_s` that
        turn the sum of squares into the mean Delta E.
    range_check
        Optional ``(cos_theta, eta_i, weight)``: points where the model must
        stay in [0, 1]; each adds the residual ``weight * (min(F, 0) +
        max(F - 1, 0))`` per channel (zero inside), in the solves and in the
        float16 quantisation (a penalty constraint, not a clip).
    start
        Optional coefficients (3, 3, degree + 1) to start from instead of the
        variable-projection guess (a warm start from a nearby fit; the result
        is as deterministic as the start).

    Returns
    -------
    FitResult
        Never raises for non-convergence: see ``success``, ``status`` and
        ``message``.
    """
    t_start = time.perf_counter()
    eta_i_range = check_eta_i_range(eta_i_range)
    check_choice("objective", objective, OBJECTIVES)
    check_degree(degree)
    if eta_i_range[1] <= eta_i_range[0]:
        degree = 0
    target, mu, eta, weights = check_samples(target_RGB, cos_theta, eta_i, weights)
    if range_check is not None:
        check_mu, check_eta, check_weight = range_check
        check_mu = np.ravel(np.asarray(check_mu, dtype=np.float64))
        check_eta = np.ravel(np.asarray(check_eta, dtype=np.float64))
        if check_mu.size != check_eta.size or not (np.all(np.isfinite(check_mu)) and np.all(np.isfinite(check_eta))):
            raise ValueError("`range_check` must give finite cos_theta and eta_i of one size")
        if not (np.isfinite(check_weight) and check_weight > 0):
            raise ValueError(f"`range_check` weight must be a finite number > 0, got {check_weight!r}")
        range_check = (check_mu, check_eta, float(check_weight))
    problem = Problem(target, mu, eta, eta_i_range, degree, objective, weights, range_check)
    bounds = coefficient_bounds(degree)
    if start is None:
        x0 = initial_guess(target, mu, eta, eta_i_range, degree)
    else:
        x0 = np.asarray(start, dtype=np.float64)
        if x0.shape != problem.shape or not np.all(np.isfinite(x0)):
            raise ValueError(f"`start` must be finite coefficients of shape {problem.shape}, got shape {x0.shape}")
    x0 = np.clip(x0.ravel(), *bounds)
    result = solve(problem, x0, bounds, 1e-10, max_nfev)

    def delta_E(current, x):
        dE = np.linalg.norm(current.residuals(x)[: 3 * mu.size].reshape(-1, 3), axis=1)
        return dE if weights is None else dE / np.sqrt(np.maximum(weights, 1e-300))

    def resolve(sample_weights, x):
        again = problem.reweighted(sample_weights)
        return again, solve(again, x, bounds, 1e-8, max_nfev)

    # Mean Delta E, not its RMS (de2000 only).
    problem, result, nfev, njev = reweighted(
        problem,
        result,
        irls_rounds if objective == "de2000" else 0,
        delta_E,
        np.ones(mu.size) if weights is None else weights,
        resolve,
    )
    t_fit = time.perf_counter()
    C = result.x.reshape(problem.shape)
    if quantise:
        C16 = quantise_coefficients(problem, C)
    else:
        C16 = to_float16(C)
    cost16 = 0.5 * float(np.sum(problem.residuals(C16.astype(np.float64).ravel()) ** 2))
    t_end = time.perf_counter()
    return FitResult.from_solve(
        result,
        C,
        C16,
        eta_i_range,
        degree,
        objective,
        nfev,
        njev,
        cost16,
        {"fit": t_fit - t_start, "quantise": t_end - t_fit},
    )
