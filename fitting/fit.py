"""
Fitting
=======

Least-squares fit of the coated-conductor model (:mod:`fitting.model`) to
reflectance data, and the float16 coefficients actually shipped.

-   :func:`fit_coefficients`: the model fitted to RGB samples at
    (cos theta, eta_i); the core shared by material and curve fits.
-   :func:`fit_material`: from measured *n*, *k* to a float16
    :class:`fitting.pack.PackedMaterial`, with timings and metrics.
-   :func:`quantise_coefficients`: float16 coefficients that minimise the
    fitted objective (not merely the rounded float32 fit).
-   :func:`evaluate_material`: Delta E 2000 of the model and the baselines
    against the 1 nm reference on the paper's 100 x 100 grid.
-   :data:`OBJECTIVES`: ``rgb`` (the paper), ``lab`` and ``de2000``.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
Branch, M. A., Coleman, T. F., & Li, Y. (1999). A subspace, interior, and
conjugate gradient method for large-scale bound-constrained minimization
problems. SIAM J. Sci. Comput., 21(1), 1-23 (trust-region reflective).
Sharma, G., Wu, W., & Dalal, E. N. (2005). The CIEDE2000 color-difference formula.
Frantar, E., et al. (2023). GPTQ: Accurate post-training quantization. ICLR
(sequential rounding with second-order error compensation).
"""

from __future__ import annotations

import functools
import hashlib
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import least_squares
from threadpoolctl import ThreadpoolController

from .colorimetry import ACEScg_to_Lab, ACEScg_to_Lab_jacobian
from .metrics import baseline_metrics, error_metrics
from .model import (
    ALPHA_MIN,
    DEFAULT_ETA_I_RANGE,
    check_eta_i_range,
    coated_conductor_model,
    model_jacobian,
    normalised_eta_i,
)
from .nk import DEFAULT_MIN_COVERAGE, SpectralNK, resample_nk
from .pack import FLOAT16_MAX, PackedMaterial, to_float16
from .reference import evaluation_grid, reference_ACEScg, spectral_weights

__all__ = [
    "OBJECTIVES",
    "DEFAULT_OBJECTIVE",
    "FitSettings",
    "FitResult",
    "fit_coefficients",
    "fit_material",
    "quantise_coefficients",
    "evaluate_material",
    "fit_grid",
    "GRIDS",
]

OBJECTIVES = ("rgb", "lab", "de2000")
DEFAULT_OBJECTIVE = "de2000"
"""The objective with the lower Delta E 2000 on the library (docs/results.md)."""

# The fit's matrices are tiny (hundreds x 27): BLAS threads only add
# synchronisation cost, and oversubscribe the pool's worker processes.
_THREADPOOLS = ThreadpoolController()

_IRLS_FLOOR = 0.02  # Delta E below which samples stop gaining weight
# Box bounds of the coefficients: F0, a, alpha. Generous for every measured
# conductor (on the 22 of the library |c| < 1 for F0, < 12 for a, < 9 for
# alpha), they keep parameters the data cannot identify (alpha where a ~ 0)
# from running away, and every coefficient far inside the float16 range.
# alpha's constant term stays at or above the model's clamp.
_BOUND = np.array([16.0, 64.0, 256.0])
_ALPHA_CANDIDATES = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0, 16.0, 24.0])


@dataclass(frozen=True)
class FitSettings:
    """
    Settings of a material fit.

    Attributes
    ----------
    mu_samples, eta_samples, grid
        The fitting grid (:func:`fit_grid`): ``mu_samples`` values of cos
        theta over [0, 1] times ``eta_samples`` values of eta_i over the
        domain (1 when the domain is a single value), at Gauss-Legendre nodes
        with quadrature weights (``"gauss"``) or evenly (``"uniform"``).
    step_nm
        Spectral step of the reference used for fitting (nm).
    objective
        One of :data:`OBJECTIVES`.
    degree
        Polynomial degree in t of F0, a and alpha (0, 1 or 2); forced to 0
        for a single eta_i.
    quantise
        Choose float16 coefficients by :func:`quantise_coefficients`
        (otherwise round the float32 fit).
    max_nfev
        Evaluation budget of the trust-region solver.
    min_coverage
        Smallest covered fraction of 360-830 nm accepted.
    irls_rounds
        Reweighting rounds of the ``de2000`` objective (mean Delta E).
    """

    mu_samples: int = 12
    eta_samples: int = 4
    grid: str = "gauss"
    step_nm: float = 5.0
    objective: str = DEFAULT_OBJECTIVE
    degree: int = 2
    quantise: bool = True
    max_nfev: int = 200
    min_coverage: float = DEFAULT_MIN_COVERAGE
    irls_rounds: int = 2

    def __post_init__(self) -> None:
        if not (isinstance(self.mu_samples, int) and 4 <= self.mu_samples <= 1000):
            raise ValueError(f"`mu_samples` must be an integer in [4, 1000], got {self.mu_samples!r}")
        if not (isinstance(self.eta_samples, int) and 1 <= self.eta_samples <= 1000):
            raise ValueError(f"`eta_samples` must be an integer in [1, 1000], got {self.eta_samples!r}")
        if self.grid not in GRIDS:
            raise ValueError(f"`grid` must be one of {', '.join(GRIDS)}, got {self.grid!r}")
        if self.objective not in OBJECTIVES:
            raise ValueError(f"`objective` must be one of {', '.join(OBJECTIVES)}, got {self.objective!r}")
        if self.degree not in (0, 1, 2):
            raise ValueError(f"`degree` must be 0, 1 or 2, got {self.degree!r}")
        if not (isinstance(self.max_nfev, int) and self.max_nfev >= 1):
            raise ValueError(f"`max_nfev` must be a positive integer, got {self.max_nfev!r}")
        if not (isinstance(self.irls_rounds, int) and 0 <= self.irls_rounds <= 10):
            raise ValueError(f"`irls_rounds` must be an integer in [0, 10], got {self.irls_rounds!r}")
        if not 0.0 <= float(self.min_coverage) <= 1.0:
            raise ValueError(f"`min_coverage` must lie in [0, 1], got {self.min_coverage!r}")
        step = float(self.step_nm)
        if not (np.isfinite(step) and 0.5 <= step <= 100.0):
            raise ValueError(f"`step_nm` must lie in [0.5, 100], got {self.step_nm!r}")


@dataclass
class FitResult:
    """
    Result of a fit.

    Attributes
    ----------
    coefficients
        Float64 least-squares optimum, (3, 3, degree + 1).
    coefficients_float16
        The shipped float16 coefficients (same shape).
    eta_i_range, degree, objective
        The fitted domain, polynomial degree and objective.
    success, status, message, nfev, njev
        Convergence report of :func:`scipy.optimize.least_squares`
        (``status`` > 0 is convergence, 0 is the evaluation budget).
    cost
        Half the sum of squared (weighted) residuals of the last solve at the
        float64 optimum.
    cost_float16
        The same for the float16 coefficients.
    timings
        Seconds: ``reference``, ``fit``, ``quantise``, ``total``.
    coverage
        Fraction of 360-830 nm covered by the data (n, k fits).
    packed
        The :class:`fitting.pack.PackedMaterial` (n, k fits).
    metrics
        Filled by :func:`evaluate_material` or the caller.
    """

    coefficients: np.ndarray
    coefficients_float16: np.ndarray
    eta_i_range: tuple[float, float]
    degree: int
    objective: str
    success: bool
    status: int
    message: str
    nfev: int
    njev: int
    cost: float
    cost_float16: float
    timings: dict[str, float] = field(default_factory=dict)
    coverage: float = 1.0
    packed: PackedMaterial | None = None
    metrics: dict[str, Any] = field(default_factory=dict)

    @property
    def iterations(self) -> int:
        """Jacobian evaluations, one per accepted trust-region step."""
        return self.njev

    def summary(self) -> dict[str, Any]:
        """JSON-friendly report of the convergence and timings."""
        return {
            "success": self.success,
            "status": self.status,
            "message": self.message,
            "iterations": self.iterations,
            "nfev": self.nfev,
            "cost": self.cost,
            "cost_float16": self.cost_float16,
            "objective": self.objective,
            "degree": self.degree,
            "coverage": self.coverage,
            "timings": dict(self.timings),
        }


GRIDS = ("gauss", "uniform")


def fit_grid(
    eta_i_range: tuple[float, float],
    mu_samples: int = 12,
    eta_samples: int = 4,
    kind: str = "gauss",
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Flattened fitting grid over [0, 1] x ``eta_i_range`` with sample weights.

    The error the fit is judged by is the mean over a fine uniform grid, an
    approximation of the integral over (cos theta, eta_i). ``"gauss"`` places
    the samples at Gauss-Legendre nodes with their quadrature weights, which
    integrate smooth functions exactly to degree 2n - 1, so a small grid
    stands for the fine one; ``"uniform"`` spaces them evenly with equal
    weights. A single eta_i (lo = hi) gives one row.

    Returns
    -------
    tuple
        ``cos_theta``, ``eta_i`` and ``weights`` (mean 1), each flattened
        (samples indexed [eta_i, cos_theta]).
    """
    if kind not in GRIDS:
        raise ValueError(f"`kind` must be one of {', '.join(GRIDS)}, got {kind!r}")
    lo, hi = eta_i_range

    def axis(n, a, b):
        if kind == "uniform":
            return np.linspace(a, b, n), np.ones(n)
        x, w = np.polynomial.legendre.leggauss(n)
        return a + 0.5 * (x + 1.0) * (b - a), w

    mu, w_mu = axis(mu_samples, 0.0, 1.0)
    eta, w_eta = (np.array([lo]), np.ones(1)) if hi <= lo else axis(eta_samples, lo, hi)
    E, M = np.meshgrid(eta, mu, indexing="ij")
    W = np.outer(w_eta, w_mu)
    return M.ravel(), E.ravel(), (W / W.mean()).ravel()


def _de2000_weights(Lab_ref: np.ndarray) -> np.ndarray:
    """
    Per-sample 3 x 3 maps A with ``|A dLab|`` the CIEDE2000 difference to
    first order around the reference colour (Sharma et al. 2005, Eq. 1-22):
    rows dL'/S_L, dC'/S_C + R_T/2 dH'/S_H and sqrt(1 - R_T^2/4) dH'/S_H.
    """
    L, a, b = Lab_ref[:, 0], Lab_ref[:, 1], Lab_ref[:, 2]
    C = np.hypot(a, b)
    C7 = C**7
    G = 0.5 * (1.0 - np.sqrt(C7 / (C7 + 25.0**7)))
    a1 = (1.0 + G) * a
    C1 = np.hypot(a1, b)
    h = np.arctan2(b, a1)
    h_deg = np.degrees(h) % 360.0
    # Achromatic colours have no hue direction: any orthonormal pair serves.
    safe = C1 > 1e-9
    cos_h = np.where(safe, a1 / np.where(safe, C1, 1.0), 1.0)
    sin_h = np.where(safe, b / np.where(safe, C1, 1.0), 0.0)
    SL = 1.0 + 0.015 * (L - 50.0) ** 2 / np.sqrt(20.0 + (L - 50.0) ** 2)
    SC = 1.0 + 0.045 * C1
    T = (
        1.0 - 0.17 * np.cos(np.radians(h_deg - 30.0)) + 0.24 * np.cos(np.radians(2.0 * h_deg))
        + 0.32 * np.cos(np.radians(3.0 * h_deg + 6.0)) - 0.20 * np.cos(np.radians(4.0 * h_deg - 63.0))
    )
    SH = 1.0 + 0.015 * C1 * T
    C17 = C1**7
    RT = -np.sin(np.radians(2.0 * 30.0 * np.exp(-(((h_deg - 275.0) / 25.0) ** 2)))) * 2.0 * np.sqrt(
        C17 / (C17 + 25.0**7)
    )
    A = np.zeros((L.size, 3, 3))
    A[:, 0, 0] = 1.0 / SL
    # dC' = cos_h da' + sin_h db, dH' = -sin_h da' + cos_h db, da' = (1 + G) da.
    dC = np.stack([np.zeros_like(L), (1.0 + G) * cos_h, sin_h], axis=-1)
    dH = np.stack([np.zeros_like(L), -(1.0 + G) * sin_h, cos_h], axis=-1)
    A[:, 1, :] = dC / SC[:, None] + (RT / 2.0)[:, None] * dH / SH[:, None]
    A[:, 2, :] = np.sqrt(np.clip(1.0 - RT**2 / 4.0, 0.0, 1.0))[:, None] * dH / SH[:, None]
    return A


class _Problem:
    """Residuals and Jacobian of one fit (flattened samples S, 3 outputs each)."""

    def __init__(self, target_RGB, cos_theta, eta_i, eta_i_range, degree, objective, weights=None,
                 range_check=None):
        # range_check: (mu, eta, weight) of points where the model must stay
        # in [0, 1]: one hinge residual weight * (min(F, 0) + max(F - 1, 0))
        # per point and channel, 0 while the model is inside.
        self.check = None if range_check is None else (
            np.ravel(range_check[0]), np.ravel(range_check[1]), float(range_check[2]))
        self.mu = np.ravel(cos_theta)
        self.eta = np.ravel(eta_i)
        self.range = eta_i_range
        self.shape = (3, 3, degree + 1)
        self.objective = objective
        self.target = np.asarray(target_RGB, dtype=np.float64).reshape(-1, 3)
        self.sqrt_w = None if weights is None else np.sqrt(np.ravel(weights))[:, None]
        if objective == "rgb":
            self.target_out = self.target
        else:
            self.target_out = ACEScg_to_Lab(self.target)
            self.A = _de2000_weights(self.target_out) if objective == "de2000" else None

    def _outputs(self, F):
        if self.objective == "rgb":
            return F - self.target_out, None
        d = ACEScg_to_Lab(F) - self.target_out
        G = ACEScg_to_Lab_jacobian(F)
        if self.A is not None:
            d = np.einsum("sij,sj->si", self.A, d)
            G = self.A @ G
        return d, G

    def _range_residuals(self, x):
        mu, eta, weight = self.check
        F = coated_conductor_model(mu, eta, x.reshape(self.shape), self.range)
        return weight * (np.minimum(F, 0.0) + np.maximum(F - 1.0, 0.0))

    def residuals(self, x):
        F = coated_conductor_model(self.mu, self.eta, x.reshape(self.shape), self.range)
        r, _ = self._outputs(F)
        if self.sqrt_w is not None:
            r = r * self.sqrt_w
        if self.check is not None:
            return np.concatenate([r.ravel(), self._range_residuals(x).ravel()])
        return r.ravel()

    def _range_jacobian(self, x):
        mu, eta, weight = self.check
        F, Jm = model_jacobian(mu, eta, x.reshape(self.shape), self.range)
        active = ((F < 0.0) | (F > 1.0)).astype(np.float64)  # (K, 3)
        K, d1 = Jm.shape[0], self.shape[2]
        J = np.zeros((K, 3, 3, 3, d1))
        idx = np.arange(3)
        J[:, idx, :, idx, :] = (weight * active.T[:, :, None, None] * Jm.transpose(1, 0, 2, 3))
        return J.reshape(K * 3, -1)

    def jacobian(self, x):
        F, Jm = model_jacobian(self.mu, self.eta, x.reshape(self.shape), self.range)
        _, G = self._outputs(F)
        S, d1 = Jm.shape[0], self.shape[2]
        if G is None:
            J = np.zeros((S, 3, 3, 3, d1))
            idx = np.arange(3)
            J[:, idx, :, idx, :] = Jm.transpose(1, 0, 2, 3)
        else:
            # J[s, o, p, c, j] = G[s, o, c] * Jm[s, c, p, j]
            J = np.einsum("soc,scpj->sopcj", G, Jm)
        if self.sqrt_w is not None:
            J = J * self.sqrt_w[:, :, None, None, None]
        if self.check is not None:
            return np.concatenate([J.reshape(S * 3, -1), self._range_jacobian(x)])
        return J.reshape(S * 3, -1)


def _bounds(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Box bounds (lower, upper) of the flattened coefficients, see ``_BOUND``."""
    upper = np.broadcast_to(_BOUND[:, None, None], (3, 3, degree + 1)).copy()
    lower = -upper
    lower[2, :, 0] = ALPHA_MIN
    return lower.ravel(), upper.ravel()


def _solve(problem: _Problem, x0: np.ndarray, bounds, tol: float, max_nfev: int):
    """
    TRF from ``x0``, unbounded first (cheaper per iteration); the bounded
    solve is run only when the unbounded optimum leaves the box, i.e. when
    the data leave some coefficient unidentified.
    """
    lower, upper = bounds
    options = dict(jac=problem.jacobian, method="trf", x_scale="jac",
                   ftol=tol, xtol=tol, gtol=tol, max_nfev=max_nfev)
    result = least_squares(problem.residuals, x0, **options)
    if np.all(np.isfinite(result.x)) and np.all((result.x >= lower) & (result.x <= upper)):
        return result
    bounded = least_squares(problem.residuals, x0, bounds=(lower, upper), **options)
    bounded.nfev += result.nfev
    bounded.njev = (bounded.njev or 0) + (result.njev or 0)
    return bounded


def _initial_guess(target, mu, eta, eta_i_range, degree) -> np.ndarray:
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
    for alpha in _ALPHA_CANDIDATES:
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


def _single_threaded_blas(function):
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with _THREADPOOLS.limit(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return wrapper


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
    :mod:`fitting.model`, :math:`T_s` the target, and :math:`A_s` the
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

    Returns
    -------
    FitResult
        Never raises for non-convergence: see ``success``, ``status`` and
        ``message``.
    """
    t_start = time.perf_counter()
    eta_i_range = check_eta_i_range(eta_i_range)
    if objective not in OBJECTIVES:
        raise ValueError(f"`objective` must be one of {', '.join(OBJECTIVES)}, got {objective!r}")
    if degree not in (0, 1, 2):
        raise ValueError(f"`degree` must be 0, 1 or 2, got {degree!r}")
    if eta_i_range[1] <= eta_i_range[0]:
        degree = 0
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
    if range_check is not None:
        check_mu, check_eta, check_weight = range_check
        check_mu = np.ravel(np.asarray(check_mu, dtype=np.float64))
        check_eta = np.ravel(np.asarray(check_eta, dtype=np.float64))
        if check_mu.size != check_eta.size or not (np.all(np.isfinite(check_mu)) and np.all(np.isfinite(check_eta))):
            raise ValueError("`range_check` must give finite cos_theta and eta_i of one size")
        if not (np.isfinite(check_weight) and check_weight > 0):
            raise ValueError(f"`range_check` weight must be a finite number > 0, got {check_weight!r}")
        range_check = (check_mu, check_eta, float(check_weight))
    problem = _Problem(target, mu, eta, eta_i_range, degree, objective, weights, range_check)
    bounds = _bounds(degree)
    x0 = np.clip(_initial_guess(target, mu, eta, eta_i_range, degree).ravel(), *bounds)
    result = _solve(problem, x0, bounds, 1e-10, max_nfev)
    nfev, njev = result.nfev, result.njev or 0
    if objective == "de2000":
        # Mean Delta E, not its RMS: iteratively reweighted least squares with
        # w_s = 1 / max(dE_s, floor) turns sum w_s dE_s^2 into sum dE_s.
        base = np.ones(mu.size) if weights is None else weights
        for _ in range(irls_rounds):
            dE = np.linalg.norm(problem.residuals(result.x)[: 3 * mu.size].reshape(-1, 3), axis=1)
            if weights is not None:
                dE = dE / np.sqrt(np.maximum(weights, 1e-300))
            floor = max(_IRLS_FLOOR, 1e-3 * float(dE.max()))
            problem = _Problem(
                target, mu, eta, eta_i_range, degree, objective, base / np.maximum(dE, floor),
                range_check,
            )
            result = _solve(problem, result.x, bounds, 1e-8, max_nfev)
            nfev, njev = nfev + result.nfev, njev + (result.njev or 0)
    t_fit = time.perf_counter()
    C = result.x.reshape(problem.shape)
    if quantise:
        C16 = quantise_coefficients(problem, C)
    else:
        C16 = to_float16(C)
    cost16 = 0.5 * float(np.sum(problem.residuals(C16.astype(np.float64).ravel()) ** 2))
    t_end = time.perf_counter()
    return FitResult(
        coefficients=C,
        coefficients_float16=C16,
        eta_i_range=eta_i_range,
        degree=degree,
        objective=objective,
        success=bool(result.success),
        status=int(result.status),
        message=str(result.message),
        nfev=int(nfev),
        njev=int(njev),
        cost=float(result.cost),
        cost_float16=cost16,
        timings={"fit": t_fit - t_start, "quantise": t_end - t_fit},
    )


def quantise_coefficients(problem: _Problem, C: np.ndarray, passes: int = 3) -> np.ndarray:
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

    delta = np.zeros(n)
    free = np.ones(n, dtype=bool)
    for i in np.argsort(-np.diag(H)):
        target = float(np.float16(np.clip(x[i] + delta[i], -FLOAT16_MAX, FLOAT16_MAX)))
        step = target - x[i] - delta[i]
        delta[i] = target - x[i]
        free[i] = False
        if step != 0.0 and free.any():
            # Minimise q over the free coordinates given the fixed ones.
            F = np.flatnonzero(free)
            rhs = Hs[np.ix_(F, [i])].ravel() * (step * scale[i])
            delta[F] -= np.linalg.solve(Hs[np.ix_(F, F)], rhs) / scale[F]
    with np.errstate(over="ignore", invalid="ignore"):
        x16 = (x + delta).astype(np.float16)
    if not np.all(np.isfinite(x16)):
        # A near-singular compensation step left the float16 range: start
        # the coordinate moves from nearest rounding instead.
        x16 = to_float16(x)
    delta = x16.astype(np.float64) - x
    # One-ulp coordinate moves, best first. The change of q for a move s_i of
    # coordinate i alone is s_i (2 (H delta + g)_i + s_i H_ii): all moves are
    # scored at once, the best taken, the gradient updated, until none helps.
    gradient = H @ delta + g
    for _ in range(passes * n):
        with np.errstate(over="ignore", invalid="ignore"):
            up = np.nextafter(x16, np.float16(np.inf)).astype(np.float64) - x16
            down = np.nextafter(x16, np.float16(-np.inf)).astype(np.float64) - x16
        steps = np.stack([up, down])
        change = steps * (2.0 * gradient + steps * np.diag(H))
        change[~np.isfinite(change)] = np.inf
        k, i = np.unravel_index(np.argmin(change), change.shape)
        if not change[k, i] < 0.0:  # q strictly decreases: no cycles
            break
        step = steps[k, i]
        x16[i] = np.float16(x16[i] + step)
        delta[i] += step
        gradient += H[:, i] * step
    x16 = (x + delta).astype(np.float16)
    nearest = to_float16(x)
    cost = np.sum(problem.residuals(x16.astype(np.float64)) ** 2)
    cost_nearest = np.sum(problem.residuals(nearest.astype(np.float64)) ** 2)
    chosen = x16 if cost <= cost_nearest else nearest
    return to_float16(chosen.astype(np.float64)).reshape(C.shape)


def fit_material(
    nk: SpectralNK,
    eta_i_range=DEFAULT_ETA_I_RANGE,
    settings: FitSettings | None = None,
    evaluate: bool = False,
    **overrides,
) -> FitResult:
    """
    Fit the model to the spectral reference of ``nk`` over ``eta_i_range``.

    The reference on the fitting grid (:class:`FitSettings`) comes from the
    exact Fresnel equations integrated to linear ACEScg at ``step_nm``;
    :func:`fit_coefficients` fits and quantises. ``overrides`` replace
    individual settings (``objective="rgb"``, ``step_nm=1``, ...).

    Returns
    -------
    FitResult
        With ``packed`` (float16 :class:`fitting.pack.PackedMaterial`, the
        citation of ``nk`` as source), ``coverage`` and ``timings``
        (``reference``, ``fit``, ``quantise``, ``total``); with ``metrics``
        from :func:`evaluate_material` when ``evaluate`` is true.

    Raises
    ------
    ValueError
        For an invalid domain or setting, or data covering too little of
        the visible range.
    """
    t0 = time.perf_counter()
    settings = settings or FitSettings()
    if overrides:
        settings = FitSettings(**{**settings.__dict__, **overrides})
    eta_i_range = check_eta_i_range(eta_i_range)
    nodes, _ = spectral_weights(settings.step_nm)
    coverage = resample_nk(nk, nodes, settings.min_coverage).coverage
    mu, eta, weights = fit_grid(
        eta_i_range, settings.mu_samples, settings.eta_samples, settings.grid
    )
    target = reference_ACEScg(nk, mu, eta, settings.step_nm, settings.min_coverage)
    t_ref = time.perf_counter()
    result = fit_coefficients(
        target, mu, eta, eta_i_range, settings.degree, settings.objective,
        settings.max_nfev, settings.quantise, weights=weights,
        irls_rounds=settings.irls_rounds,
    )
    result.coverage = coverage
    result.timings["reference"] = t_ref - t0
    result.packed = PackedMaterial(
        name=nk.name, coefficients=result.coefficients_float16,
        eta_i_range=eta_i_range, source=nk.source,
    )
    result.timings["total"] = time.perf_counter() - t0
    if evaluate:
        result.metrics = evaluate_material(nk, result, min_coverage=settings.min_coverage)
        result.packed = PackedMaterial(
            name=nk.name, coefficients=result.coefficients_float16,
            eta_i_range=eta_i_range, source=nk.source, metrics=result.metrics,
        )
    return result


def evaluate_material(
    nk: SpectralNK, result: FitResult, samples: int = 100, baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> dict[str, Any]:
    """
    Delta E 2000 and RMSE against the 1 nm reference on the paper's grid
    (``samples`` x ``samples`` over [0, 1] x the fitted domain), for the
    float16 model, the float64 fit and (optionally) the adjusted Lazanyi and
    Schlick baselines, with the breakdown at eta_i = 1, 1.5, 2, 2.5.
    """
    lo, hi = result.eta_i_range
    M, E = evaluation_grid(samples, (lo, hi))
    ref = reference_ACEScg(nk, M, E, 1.0, min_coverage)
    rows = E[:, 0]
    out = {
        "grid": f"{samples}x{samples}",
        "model_float16": error_metrics(
            ref, coated_conductor_model(M, E, result.coefficients_float16, (lo, hi)), rows
        ),
        "model_float64": error_metrics(
            ref, coated_conductor_model(M, E, result.coefficients, (lo, hi)), rows
        ),
        "coverage": result.coverage,
    }
    if baselines:
        out.update(baseline_metrics(nk, M, E, ref, min_coverage))
    return out


def content_id(*parts: bytes | str) -> str:
    """Stable content address (hex SHA-256, 32 characters) of the inputs of a fit."""
    digest = hashlib.sha256()
    for part in parts:
        digest.update(part.encode("utf-8") if isinstance(part, str) else part)
        digest.update(b"\x00")
    return digest.hexdigest()[:32]
