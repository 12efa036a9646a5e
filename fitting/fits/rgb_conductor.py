"""
RGB conductor fits
==================

The model kind ``rgb-conductor`` (:mod:`fitting.models.rgb_conductor`)
fitted to reflectance data: per channel *n* and *k* such that the exact
Fresnel equations of the relative index :math:`(n_c + i k_c)/\\eta_i`
follow the target over the whole (cos theta, eta_i) domain, with the
objectives and grid of the material fit (:class:`fitting.fits.settings.FitSettings`),
and float16 values chosen to minimise the objective, not merely rounded
(:mod:`fitting.fits.rgb_conductor_quantise`).

-   :func:`fit_rgb_conductor_coefficients`: the fit to RGB samples.
-   :func:`fit_rgb_conductor`: from measured *n*, *k* to a float16
    :class:`fitting.models.pack.PackedMaterial` of kind ``rgb-conductor``.
-   :func:`evaluate_rgb_conductor`: Delta E 2000 against the 1 nm reference
    on the paper's 100 x 100 grid (as :func:`fitting.fits.evaluate.evaluate_material`).
-   :func:`rgb_nk`: the older yardstick of the speed-against-error report,
    per-channel n, k fitted in air (eta_i = 1) in linear RGB.

References
----------
Gulbrandsen, O. (2014). Artist friendly metallic Fresnel. JCGT, 3(4), 64-72.
Pharr, M., Jakob, W., & Humphreys, G. (2023). Physically Based Rendering,
4th ed., Section 14.3 (``CoatedConductor``: the relative index).
Branch, M. A., Coleman, T. F., & Li, Y. (1999). Trust-region reflective
least squares. SIAM J. Sci. Comput., 21(1), 1-23.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ..colour.reference import reference_ACEScg
from ..domain import DEFAULT_ETA_I_RANGE, DEFAULT_MIN_COVERAGE, check_eta_i_range
from ..models.pack import to_float16
from ..models.rgb_conductor import MODEL_KIND
from ..optics.fresnel import fresnel_conductor, fresnel_conductor_derivatives
from ..optics.nk import SpectralNK
from .evaluate import evaluate_material
from .result import FitResult
from .rgb_conductor_quantise import N_BOUNDS, K_BOUNDS, RGBConductorObjective, nk_bounds, quantise_rgb_conductor
from .settings import OBJECTIVES, FitSettings
from .pipeline import FitKind, fit_spectral
from ..numerics import scipy_optimize
from .solver import check_samples, reweighted

__all__ = [
    "DEFAULT_SETTINGS",
    "RGB_NK_SAMPLES",
    "fit_rgb_conductor_coefficients",
    "fit_rgb_conductor",
    "evaluate_rgb_conductor",
    "rgb_nk",
]

DEFAULT_SETTINGS = FitSettings(step_nm=1.0)
"""The material fit's settings with the reference at 1 nm: the reference on the
48 samples of the 12 x 4 grid is cheap at any step, and at this kind's
accuracy (mean Delta E about 0.02) the 5 nm reference's own error is no
longer negligible (``benchmarks/rgb_conductor.py``: 0.0191 at 1 nm)."""

_N_STARTS = (0.2, 1.0, 3.0)  # starts of n per channel: the rgb problem has local minima


def _initial_guess(target, mu, eta, weights) -> np.ndarray:
    """
    Per channel, the linear-RGB least-squares fit of (n_c, k_c) from a few
    starts of n (k from the normal-incidence reflectance); the best start
    wins, so the result is deterministic.
    """
    least_squares = scipy_optimize()[0].least_squares  # imported on first use (a coated-conductor fit never does)

    lower, upper = nk_bounds()
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
                lambda x: (fresnel_conductor(mu, eta, x[0], x[1]) - R) * sqrt_w,
                start,
                jac=lambda x: (
                    np.stack(fresnel_conductor_derivatives(mu, eta, x[0], x[1])[1:], axis=1) * sqrt_w[:, None]
                ),
                bounds=([lower[c], lower[3 + c]], [upper[c], upper[3 + c]]),
                method="trf",
                xtol=1e-10,
                ftol=1e-10,
                gtol=1e-10,
            )
            if best is None or fit.cost < best.cost:
                best = fit
        x0[:, c] = best.x
    return x0


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

    with the residual of :func:`fitting.fits.solver.fit_coefficients` for each
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
        One of :data:`fitting.fits.settings.OBJECTIVES`.
    max_nfev, quantise, weights, irls_rounds
        As :func:`fitting.fits.solver.fit_coefficients`.

    Returns
    -------
    FitResult
        ``coefficients`` and ``coefficients_float16`` of shape (2, 3) (n, k
        per channel), ``model`` ``"rgb-conductor"``, ``degree`` 0; never
        raises for non-convergence (see ``success``, ``status``, ``message``).
    """
    least_squares = scipy_optimize()[0].least_squares  # imported on first use (a coated-conductor fit never does)

    t_start = time.perf_counter()
    eta_i_range = check_eta_i_range(eta_i_range)
    if objective not in OBJECTIVES:
        raise ValueError(f"`objective` must be one of {', '.join(OBJECTIVES)}, got {objective!r}")
    target, mu, eta, weights = check_samples(target_RGB, cos_theta, eta_i, weights)
    if np.any(eta < 1.0):
        raise ValueError(f"`eta_i` must be >= 1, got {eta.min():g}")
    base = np.ones(mu.size) if weights is None else weights
    bounds = nk_bounds()
    x = _initial_guess(target, mu, eta, base).ravel()
    problem = RGBConductorObjective(target, mu, eta, objective, base)
    options = dict(bounds=bounds, method="trf", x_scale="jac", max_nfev=max_nfev)
    result = least_squares(problem.residuals, x, jac=problem.jacobian, ftol=1e-10, xtol=1e-10, gtol=1e-10, **options)
    unweighted = RGBConductorObjective(target, mu, eta, objective, None)

    def resolve(sample_weights, x):
        again = RGBConductorObjective(target, mu, eta, objective, sample_weights)
        return again, least_squares(again.residuals, x, jac=again.jacobian, ftol=1e-8, xtol=1e-8, gtol=1e-8, **options)

    problem, result, nfev, njev = reweighted(
        problem,
        result,
        irls_rounds if objective == "de2000" else 0,
        lambda _, x: np.linalg.norm(unweighted.residuals(x).reshape(-1, 3), axis=1),
        base,
        resolve,
    )
    t_fit = time.perf_counter()
    C = result.x.reshape(2, 3)
    scorer = RGBConductorObjective(target, mu, eta, objective, base)
    C16 = quantise_rgb_conductor(scorer, C) if quantise else to_float16(C)
    cost16 = 0.5 * float(np.sum(problem.residuals(C16.astype(np.float64).ravel()) ** 2))
    t_end = time.perf_counter()
    return FitResult.from_solve(
        result,
        C,
        C16,
        eta_i_range,
        0,
        objective,
        nfev,
        njev,
        cost16,
        {"fit": t_fit - t_start, "quantise": t_end - t_fit},
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
    :func:`fitting.fits.material.fit_material`; ``degree`` does not apply), by
    default :data:`DEFAULT_SETTINGS`.

    Returns
    -------
    FitResult
        With ``packed`` (a :class:`fitting.models.pack.PackedMaterial` of model
        ``rgb-conductor``), ``coverage``, ``timings`` and, when ``evaluate``
        is true, ``metrics`` from :func:`evaluate_rgb_conductor`.

    Raises
    ------
    ValueError
        For an invalid domain or setting, or data covering too little of
        the visible range.
    """
    return fit_spectral(RGB_CONDUCTOR_FIT, nk, eta_i_range, settings, evaluate, **overrides)


def evaluate_rgb_conductor(
    nk: SpectralNK,
    result: FitResult,
    samples: int = 100,
    baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    dtype: str = "float64",
) -> dict[str, Any]:
    """
    Delta E 2000 and RMSE against the 1 nm reference on the paper's grid
    (``samples`` x ``samples`` over [0, 1] x the fitted domain) for the
    float16 and float64 n, k, and (optionally) the baselines; the JSON of
    :func:`fitting.fits.evaluate.evaluate_material`. Sets ``result.error``
    to the float16 model's :class:`fitting.fits.metrics.ErrorMetrics`
    (:func:`fitting.fits.evaluate.evaluate_material`, which scores either kind).
    """
    return evaluate_material(nk, result, samples, baselines, min_coverage, dtype)


RGB_CONDUCTOR_FIT = FitKind(
    name=MODEL_KIND,
    settings=DEFAULT_SETTINGS,
    solve=lambda target, mu, eta, eta_i_range, degree, objective, max_nfev, quantise, weights=None, irls_rounds=2: (
        fit_rgb_conductor_coefficients(
            target, mu, eta, eta_i_range, objective, max_nfev, quantise, weights=weights, irls_rounds=irls_rounds
        )
    ),
    bounded=True,
)
"""The rgb-conductor's fit (:mod:`fitting.fits.pipeline`; registered in :mod:`fitting.fits.kinds`)."""


RGB_NK_SAMPLES = 64
"""Values of cos theta, evenly over [0, 1], at which (n_c, k_c) are fitted."""


def rgb_nk(
    nk: SpectralNK, step_nm: float = 1.0, min_coverage: float = DEFAULT_MIN_COVERAGE
) -> tuple[np.ndarray, np.ndarray]:
    """
    Per-channel complex index of a material for the exact RGB Fresnel term.

    For each channel *c*, solves

    .. math::

        \\min_{n_c, k_c} \\sum_s \\bigl(F(\\mu_s, 1; n_c, k_c) - R_c(\\mu_s)\\bigr)^2

    with :math:`F` the exact unpolarised Fresnel reflectance in air,
    :math:`R_c` channel *c* of the spectral reference (linear ACEScg) and
    :math:`\\mu_s` :data:`RGB_NK_SAMPLES` values evenly over [0, 1], by the
    trust-region reflective method from the start :math:`n = 1`, :math:`k`
    from F0 (deterministic), within n in [1e-3, 20], k in [0, 50].

    Parameters
    ----------
    nk
        Measured spectral *n*, *k*.
    step_nm
        Spectral step of the reference (nm).
    min_coverage
        Smallest covered fraction of 360-830 nm accepted.

    Returns
    -------
    tuple
        ``n`` and ``k``, each shape (3,) for R, G, B.

    Raises
    ------
    ValueError
        For data covering too little of the visible range.
    """
    least_squares = scipy_optimize()[0].least_squares  # imported on first use (a coated-conductor fit never does)

    mu = np.linspace(0.0, 1.0, RGB_NK_SAMPLES)
    target = reference_ACEScg(nk, mu, 1.0, step_nm, min_coverage)
    n_out, k_out = np.empty(3), np.empty(3)
    for c in range(3):
        R = target[:, c]
        # At normal incidence with n = 1 the reflectance is k^2 / (4 + k^2).
        F0 = float(np.clip(R[-1], 0.0, 0.999))
        x0 = np.array([1.0, np.sqrt(4.0 * F0 / (1.0 - F0))])
        fit = least_squares(
            lambda x: fresnel_conductor(mu, 1.0, x[0], x[1]) - R,
            np.clip(x0, [N_BOUNDS[0], K_BOUNDS[0]], [N_BOUNDS[1], K_BOUNDS[1]]),
            bounds=([N_BOUNDS[0], K_BOUNDS[0]], [N_BOUNDS[1], K_BOUNDS[1]]),
            method="trf",
            xtol=1e-12,
            ftol=1e-12,
            gtol=1e-12,
        )
        n_out[c], k_out[c] = fit.x
    return n_out, k_out
