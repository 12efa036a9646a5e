"""
RGB conductor fit
=================

The model kind ``rgb-conductor`` (:mod:`fitting.models.rgb_conductor`)
fitted to reflectance data: per channel *n* and *k* such that the exact
Fresnel equations of the relative index :math:`(n_c + i k_c)/\\eta_i`
follow the target over the whole (cos theta, eta_i) domain, with the
objectives, grid and spectral step of the material fit
(:class:`fitting.fit.FitSettings`), and float16 values chosen to minimise
the objective, not merely rounded.

-   :func:`fit_rgb_conductor_coefficients`: the fit to RGB samples.
-   :func:`quantise_rgb_conductor`: float16 n, k minimising the objective.
-   :func:`fit_rgb_conductor`: from measured *n*, *k* to a float16
    :class:`fitting.pack.PackedMaterial` of kind ``rgb-conductor``.
-   :func:`evaluate_rgb_conductor`: Delta E 2000 against the 1 nm reference
    on the paper's 100 x 100 grid (as :func:`fitting.fit.evaluate_material`).

References
----------
Pharr, M., Jakob, W., & Humphreys, G. (2023). Physically Based Rendering,
4th ed., Section 14.3 (``CoatedConductor``: the relative index).
Branch, M. A., Coleman, T. F., & Li, Y. (1999). Trust-region reflective
least squares. SIAM J. Sci. Comput., 21(1), 1-23.
Sharma, G., Wu, W., & Dalal, E. N. (2005). The CIEDE2000 color-difference formula.
"""

from __future__ import annotations

import itertools
import time
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from ..colorimetry import ACEScg_to_Lab, delta_E_2000
from ..fresnel import fresnel_conductor
from ..fit import OBJECTIVES, FitResult, FitSettings, _de2000_weights, fit_grid
from ..metrics import baseline_metrics, error_metrics
from ..model import DEFAULT_ETA_I_RANGE, check_eta_i_range
from ..models.rgb_conductor import MODEL_KIND, rgb_conductor_model
from ..nk import DEFAULT_MIN_COVERAGE, SpectralNK, resample_nk
from ..pack import PackedMaterial, to_float16
from ..reference import evaluation_grid, reference_ACEScg, spectral_weights

__all__ = [
    "DEFAULT_SETTINGS",
    "N_BOUNDS",
    "K_BOUNDS",
    "fit_rgb_conductor_coefficients",
    "quantise_rgb_conductor",
    "fit_rgb_conductor",
    "evaluate_rgb_conductor",
]

N_BOUNDS = (1.0e-3, 20.0)
"""Bounds of n per channel: n > 0 as for any SpectralNK; every conductor of
the library has n < 5 in 360-830 nm."""
K_BOUNDS = (0.0, 50.0)
"""Bounds of k per channel; the library's conductors have k < 12."""

DEFAULT_SETTINGS = FitSettings(step_nm=1.0)
"""The material fit's settings with the reference at 1 nm: six unknowns fit in
milliseconds on the 12 x 4 grid, and at this kind's accuracy (mean Delta E
about 0.02) the 5 nm reference's own error is no longer negligible
(``benchmarks/rgb_conductor.py``: 0.0192 at 1 nm)."""

_IRLS_FLOOR = 0.02  # Delta E below which samples stop gaining weight, as the material fit
_N_STARTS = (0.2, 1.0, 3.0)  # starts of n per channel: the rgb problem has local minima


class _Objective:
    """Residuals of one fit: samples S, 3 outputs each (rgb, Lab or first-order CIEDE2000)."""

    def __init__(self, target, mu, eta, objective, weights):
        self.mu, self.eta, self.objective = mu, eta, objective
        self.target = target
        self.w = np.ones(mu.size) if weights is None else weights
        if objective == "rgb":
            self.target_out = target
        else:
            self.target_out = ACEScg_to_Lab(target)
            self.A = _de2000_weights(self.target_out) if objective == "de2000" else None

    def outputs(self, F):
        if self.objective == "rgb":
            return F - self.target_out
        d = ACEScg_to_Lab(F) - self.target_out
        if self.A is not None:
            d = np.einsum("sij,sj->si", self.A, d)
        return d

    def residuals(self, x):
        F = rgb_conductor_model(self.mu, self.eta, x.reshape(2, 3))
        return (self.outputs(F) * np.sqrt(self.w)[:, None]).ravel()

    def score(self, F):
        """
        The objective itself for reflectances ``F`` of shape (..., S, 3):
        the weighted sum of squared residuals (``rgb``, ``lab``), or the
        weighted sum of CIEDE2000 differences (``de2000``, which the
        reweighted least squares approaches).
        """
        if self.objective == "de2000":
            dE = delta_E_2000(np.broadcast_to(ACEScg_to_Lab(self.target), F.shape), ACEScg_to_Lab(F))
            return np.sum(dE * self.w, axis=-1)
        if self.objective == "rgb":
            d = F - self.target_out
        else:
            d = ACEScg_to_Lab(F) - self.target_out
        return np.sum(np.sum(d * d, axis=-1) * self.w, axis=-1)


def _bounds():
    lower = np.array([N_BOUNDS[0]] * 3 + [K_BOUNDS[0]] * 3)
    upper = np.array([N_BOUNDS[1]] * 3 + [K_BOUNDS[1]] * 3)
    return lower, upper


def _initial_guess(target, mu, eta, weights) -> np.ndarray:
    """
    Per channel, the linear-RGB least-squares fit of (n_c, k_c) from a few
    starts of n (k from the normal-incidence reflectance); the best start
    wins, so the result is deterministic.
    """
    lower, upper = _bounds()
    sqrt_w = np.sqrt(weights)
    x0 = np.empty((2, 3))
    # The sample nearest normal incidence in the lowest coating fixes k for a start.
    normal = np.lexsort((-mu, eta))[0]
    eta_0 = eta[normal]
    for c in range(3):
        R = target[:, c]
        F0 = float(np.clip(R[normal], 0.0, 0.999))
        best = None
        for n in _N_STARTS:
            # F0 = ((n - eta)^2 + k^2) / ((n + eta)^2 + k^2), solved for k^2.
            k2 = (F0 * (n + eta_0) ** 2 - (n - eta_0) ** 2) / (1.0 - F0)
            start = np.clip([n, np.sqrt(max(k2, 0.0))], [lower[c], lower[3 + c]], [upper[c], upper[3 + c]])
            fit = least_squares(
                lambda x: (rgb_conductor_model(mu, eta, np.array([[x[0]] * 3, [x[1]] * 3]))[:, c] - R) * sqrt_w,
                start, bounds=([lower[c], lower[3 + c]], [upper[c], upper[3 + c]]),
                method="trf", xtol=1e-10, ftol=1e-10, gtol=1e-10,
            )
            if best is None or fit.cost < best.cost:
                best = fit
        x0[:, c] = best.x
    return x0


def _lattice(value: float, radius: int, lo: float, hi: float) -> np.ndarray:
    """The float16 values nearest ``value``, ``radius`` on either side, clipped to [lo, hi]."""
    h = np.float16(value)
    below = h if float(h) <= value else np.nextafter(h, np.float16(-np.inf))
    values = [below]
    for _ in range(radius - 1):
        values.insert(0, np.nextafter(values[0], np.float16(-np.inf)))
    above = np.nextafter(below, np.float16(np.inf))
    values.append(above)
    for _ in range(radius - 1):
        values.append(np.nextafter(values[-1], np.float16(np.inf)))
    out = np.array(values, dtype=np.float64)
    out = np.unique(np.clip(out, lo, hi))
    return out[np.isfinite(out)]


def quantise_rgb_conductor(
    objective: _Objective, x: np.ndarray, radius: int = 8, keep: int = 8, passes: int = 8
) -> np.ndarray:
    """
    Float16 n, k that minimise the fit's objective near the float64 optimum.

    The objective is the fit's own (:meth:`_Objective.score`: the weighted
    CIEDE2000 sum for ``de2000``, not its quadratic model). n and k of a
    channel are strongly correlated (the error has a long valley), so the
    best lattice point can lie several ulps from the optimum:

    1.  per channel, every pair of the ``radius`` float16 values either side
        of n and of k is scored with the other channels at the optimum,
        and the ``keep`` best pairs are kept;
    2.  every combination of the kept pairs of the three channels
        (``keep``^3) is scored; the best is taken;
    3.  one-ulp moves of single values are taken while they lower the
        objective.

    Plain rounding is among the candidates of step 1 but may be screened
    out; the result is compared with it and the better kept, so it is never
    worse than plain rounding on the fitting grid.
    """
    x = np.asarray(x, dtype=np.float64).reshape(2, 3)
    lower, upper = _bounds()
    mu, eta = objective.mu, objective.eta
    F_opt = rgb_conductor_model(mu, eta, x)
    kept = []  # per channel: (keep, 2) pairs of (n, k) and their (keep, S) reflectance
    for c in range(3):
        ns = _lattice(x[0, c], radius, lower[c], upper[c])
        ks = _lattice(x[1, c], radius, lower[3 + c], upper[3 + c])
        pairs = np.array(list(itertools.product(ns, ks)))
        C = np.zeros((2, 3, pairs.shape[0]))
        C[0] = 1.0
        C[:, c, :] = pairs.T
        # One evaluation for all pairs: channel c of each, the others at the optimum.
        F_c = fresnel_conductor(mu[None, :], eta[None, :], pairs[:, :1], pairs[:, 1:])
        F = np.broadcast_to(F_opt, (pairs.shape[0],) + F_opt.shape).copy()
        F[:, :, c] = F_c
        best = np.argsort(objective.score(F), kind="stable")[:keep]
        kept.append((pairs[best], F_c[best]))
    combos = np.array(list(itertools.product(*(range(len(k[0])) for k in kept))))
    F = np.stack([kept[c][1][combos[:, c]] for c in range(3)], axis=-1)
    scores = objective.score(F)
    i = int(np.argmin(scores))
    h = np.array([kept[c][0][combos[i, c]] for c in range(3)]).T.astype(np.float16)
    current = float(scores[i])
    # One-ulp moves from the best (the screening may have left the optimum at an edge).
    for _ in range(passes * 6):
        moves = []
        for p, c in itertools.product(range(2), range(3)):
            for direction in (np.float16(-np.inf), np.float16(np.inf)):
                trial = h.copy()
                trial[p, c] = np.nextafter(h[p, c], direction)
                value = float(trial[p, c])
                if np.isfinite(value) and lower[3 * p + c] <= value <= upper[3 * p + c]:
                    moves.append(trial)
        F = np.stack([rgb_conductor_model(mu, eta, t.astype(np.float64)) for t in moves])
        trial_scores = objective.score(F)
        j = int(np.argmin(trial_scores))
        if not trial_scores[j] < current:
            break
        h, current = moves[j], float(trial_scores[j])
    nearest = to_float16(x)
    nearest_score = float(objective.score(rgb_conductor_model(mu, eta, nearest.astype(np.float64))))
    return h if current <= nearest_score else nearest


def fit_rgb_conductor_coefficients(
    target_RGB,
    cos_theta,
    eta_i,
    eta_i_range=DEFAULT_ETA_I_RANGE,
    objective: str = "de2000",
    max_nfev: int = 200,
    quantise: bool = True,
    weights=None,
    irls_rounds: int = 2,
) -> FitResult:
    """
    Fit per-channel n, k of the exact RGB conductor Fresnel to linear ACEScg samples.

    Solves, with the trust-region reflective method,

    .. math::

        \\min_{n, k \\in \\mathbb{R}^3} \\tfrac12 \\sum_s w_s \\lVert r_s \\rVert^2,
        \\qquad r_s = \\text{residual of } F(\\mu_s; (n + i k)/\\eta_s) - T_s

    with the residual of :func:`fitting.fit.fit_coefficients` for each
    objective (linear RGB, Lab, first-order CIEDE2000), within
    :data:`N_BOUNDS` x :data:`K_BOUNDS`. For ``de2000``, ``irls_rounds``
    rounds reweight :math:`w_s` by :math:`1/\\max(\\Delta E_s, 0.02)` so that
    the optimum approaches the mean Delta E. The start is the per-channel
    linear-RGB fit from a few starts (deterministic). Stopping:
    ``ftol = xtol = gtol = 1e-10`` or ``max_nfev`` evaluations per solve.
    The float16 values then minimise the objective over the float16
    lattice near the optimum (:func:`quantise_rgb_conductor`).

    Parameters
    ----------
    target_RGB
        (S, 3) linear ACEScg reflectance in [0, 1].
    cos_theta, eta_i
        (S,) sample positions: :math:`\\mu` in [0, 1], eta_i in the domain.
    eta_i_range
        Domain [lo, hi] of eta_i, 1 <= lo <= hi <= 3 (recorded; the model
        does not depend on it).
    objective
        One of :data:`fitting.fit.OBJECTIVES`.
    max_nfev, quantise, weights, irls_rounds
        As :func:`fitting.fit.fit_coefficients`.

    Returns
    -------
    FitResult
        ``coefficients`` and ``coefficients_float16`` of shape (2, 3) (n, k
        per channel), ``model`` ``"rgb-conductor"``, ``degree`` 0; never
        raises for non-convergence (see ``success``, ``status``, ``message``).
    """
    t_start = time.perf_counter()
    eta_i_range = check_eta_i_range(eta_i_range)
    if objective not in OBJECTIVES:
        raise ValueError(f"`objective` must be one of {', '.join(OBJECTIVES)}, got {objective!r}")
    target = np.asarray(target_RGB, dtype=np.float64).reshape(-1, 3)
    mu = np.ravel(np.asarray(cos_theta, dtype=np.float64))
    eta = np.ravel(np.asarray(eta_i, dtype=np.float64))
    if not (mu.size == eta.size == target.shape[0]):
        raise ValueError("`target_RGB`, `cos_theta` and `eta_i` must have the same number of samples")
    for name, values in (("target_RGB", target), ("cos_theta", mu), ("eta_i", eta)):
        if not np.all(np.isfinite(values)):
            raise ValueError(f"`{name}` must be finite")
    if np.any(eta < 1.0):
        raise ValueError(f"`eta_i` must be >= 1, got {eta.min():g}")
    if weights is None:
        base = np.ones(mu.size)
    else:
        base = np.ravel(np.asarray(weights, dtype=np.float64))
        if base.size != mu.size or np.any(base < 0) or not np.all(np.isfinite(base)):
            raise ValueError("`weights` must be one finite value >= 0 per sample")
    bounds = _bounds()
    x = _initial_guess(target, mu, eta, base).ravel()
    problem = _Objective(target, mu, eta, objective, base)
    options = dict(bounds=bounds, method="trf", x_scale="jac", max_nfev=max_nfev)
    result = least_squares(problem.residuals, x, ftol=1e-10, xtol=1e-10, gtol=1e-10, **options)
    nfev, njev = result.nfev, result.njev or 0
    if objective == "de2000":
        for _ in range(irls_rounds):
            dE = np.linalg.norm(_Objective(target, mu, eta, objective, None).residuals(result.x).reshape(-1, 3), axis=1)
            floor = max(_IRLS_FLOOR, 1e-3 * float(dE.max()))
            problem = _Objective(target, mu, eta, objective, base / np.maximum(dE, floor))
            result = least_squares(problem.residuals, result.x, ftol=1e-8, xtol=1e-8, gtol=1e-8, **options)
            nfev, njev = nfev + result.nfev, njev + (result.njev or 0)
    t_fit = time.perf_counter()
    C = result.x.reshape(2, 3)
    scorer = _Objective(target, mu, eta, objective, base)
    C16 = quantise_rgb_conductor(scorer, C) if quantise else to_float16(C)
    cost16 = 0.5 * float(np.sum(problem.residuals(C16.astype(np.float64).ravel()) ** 2))
    t_end = time.perf_counter()
    return FitResult(
        coefficients=C,
        coefficients_float16=C16,
        eta_i_range=eta_i_range,
        degree=0,
        objective=objective,
        success=bool(result.success),
        status=int(result.status),
        message=str(result.message),
        nfev=int(nfev),
        njev=int(njev),
        cost=float(result.cost),
        cost_float16=cost16,
        timings={"fit": t_fit - t_start, "quantise": t_end - t_fit},
        model=MODEL_KIND,
    )


def fit_rgb_conductor(
    nk: SpectralNK,
    eta_i_range=DEFAULT_ETA_I_RANGE,
    settings: FitSettings | None = None,
    evaluate: bool = False,
    **overrides,
) -> FitResult:
    """
    Fit the ``rgb-conductor`` kind to the spectral reference of ``nk`` over
    ``eta_i_range``, on the grid of ``settings`` (that of
    :func:`fitting.fit.fit_material`; ``degree`` does not apply), by
    default :data:`DEFAULT_SETTINGS`.

    Returns
    -------
    FitResult
        With ``packed`` (a :class:`fitting.pack.PackedMaterial` of model
        ``rgb-conductor``), ``coverage``, ``timings`` and, when ``evaluate``
        is true, ``metrics`` from :func:`evaluate_rgb_conductor`.

    Raises
    ------
    ValueError
        For an invalid domain or setting, or data covering too little of
        the visible range.
    """
    t0 = time.perf_counter()
    settings = settings or DEFAULT_SETTINGS
    if overrides:
        settings = FitSettings(**{**settings.__dict__, **overrides})
    eta_i_range = check_eta_i_range(eta_i_range)
    nodes, _ = spectral_weights(settings.step_nm)
    coverage = resample_nk(nk, nodes, settings.min_coverage).coverage
    mu, eta, weights = fit_grid(eta_i_range, settings.mu_samples, settings.eta_samples, settings.grid)
    target = reference_ACEScg(nk, mu, eta, settings.step_nm, settings.min_coverage)
    t_ref = time.perf_counter()
    result = fit_rgb_conductor_coefficients(
        target, mu, eta, eta_i_range, settings.objective, settings.max_nfev,
        settings.quantise, weights=weights, irls_rounds=settings.irls_rounds,
    )
    result.coverage = coverage
    result.timings["reference"] = t_ref - t0
    if evaluate:
        result.metrics = evaluate_rgb_conductor(nk, result, min_coverage=settings.min_coverage)
    result.packed = PackedMaterial(
        name=nk.name, coefficients=result.coefficients_float16, eta_i_range=eta_i_range,
        source=nk.source, metrics=result.metrics, model=MODEL_KIND,
    )
    result.timings["total"] = time.perf_counter() - t0
    return result


def evaluate_rgb_conductor(
    nk: SpectralNK, result: FitResult, samples: int = 100, baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> dict[str, Any]:
    """
    Delta E 2000 and RMSE against the 1 nm reference on the paper's grid
    (``samples`` x ``samples`` over [0, 1] x the fitted domain) for the
    float16 and float64 n, k, and (optionally) the baselines; the same
    shape as :func:`fitting.fit.evaluate_material`.
    """
    lo, hi = result.eta_i_range
    M, E = evaluation_grid(samples, (lo, hi))
    ref = reference_ACEScg(nk, M, E, 1.0, min_coverage)
    rows = E[:, 0]
    out = {
        "grid": f"{samples}x{samples}",
        "model_float16": error_metrics(ref, rgb_conductor_model(M, E, result.coefficients_float16), rows),
        "model_float64": error_metrics(ref, rgb_conductor_model(M, E, result.coefficients), rows),
        "coverage": result.coverage,
    }
    if baselines:
        out.update(baseline_metrics(nk, M, E, ref, min_coverage))
    return out
