"""
The fit pipeline
================

One pipeline for every model kind: settings -> the spectral reference on the
fitting grid -> the kind's solve and float16 quantisation -> the pack
material -> (on request) the metrics -> the :class:`~fitting.fits.result.FitResult`,
whose ``settings`` are the settings that ran (its provenance) and whose
``timings["total"]`` is the whole call, evaluation included, for every kind.

-   :class:`FitKind`: a model kind's fit: its default settings and its
    solve of RGB samples (one per kind, registered in
    :mod:`fitting.fits.kinds`).
-   :func:`fit_spectral`: measured *n*, *k* to a fitted, packed material.
-   :class:`FitProblem`, :func:`fit_problem`, :func:`solve_problem`,
    :func:`guard_problem`, :func:`finish_fit`: its stages, for callers that
    share one reference between fits (a scene's candidates) or assess only
    the fit they keep.
-   :func:`settings_with`: settings with individual fields replaced.
-   :func:`with_metrics`: a result given its metrics JSON, its pack record rebuilt with them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np

from ..colour.reference import DTYPES, reference_ACEScg, spectral_weights
from ..domain import check_eta_i_range
from ..models.kinds import model_kind
from ..models.pack import PackedMaterial
from ..optics.nk import SpectralNK, resample_nk
from ..optics.quality import check_gaps, outlier_warnings
from .evaluate import evaluate_material
from .fit_quality import data_uncertainty, provenance, uncertainty_warning
from .result import FitResult
from .settings import FitSettings, fit_grid
from ..numerics.plain import unique

__all__ = [
    "FitKind",
    "FitProblem",
    "fit_problem",
    "solve_problem",
    "guard_problem",
    "finish_fit",
    "fit_spectral",
    "settings_with",
    "with_metrics",
]


@dataclass(frozen=True)
class FitKind:
    """
    How one model kind is fitted.

    Attributes
    ----------
    name
        The model kind (:data:`fitting.models.kinds.MODEL_KINDS`).
    settings
        Default :class:`~fitting.fits.settings.FitSettings` of its material fits.
    solve
        ``solve(target (S, 3), cos_theta (S,), eta_i (S,), eta_i_range, degree,
        objective, max_nfev, quantise, weights=None, irls_rounds=2, **extra)
        -> FitResult``: the least-squares fit to linear ACEScg samples and its
        float16 coefficients (``degree`` is ignored by a kind without a power
        axis). A kind whose model can leave [0, 1] also takes ``range_check``
        and ``start`` (:func:`fitting.fits.solver.fit_coefficients`).
    bounded
        True when the kind's model is a reflectance in [0, 1] by
        construction (no range constraint in curve fits).
    guard
        ``guard(nk, target, cos_theta, eta_i, weights, eta_i_range, settings,
        mean_fit, rows=None) -> FitResult``: the fit with its max guarded
        against the paper's method (:mod:`fitting.fits.guarded`), or None
        for a kind without one; ``rows``: the eta_i rows to guard at when
        ``samples`` replaced the grid (a scene's set), else None (the
        domain). Run when ``settings.guard_max`` and the objective is not
        the paper's own ``rgb``.
    quality
        ``quality(result, eta_i_range, warnings) -> dict``: what the fit can be
        trusted for (:mod:`fitting.fits.fit_quality`: the proof of [0, 1] and
        the warnings), or None for the data's warnings only.
    """

    name: str
    settings: FitSettings
    solve: Callable[..., FitResult]
    bounded: bool = False
    guard: Callable[..., FitResult] | None = None
    quality: Callable[..., dict] | None = None


def settings_with(settings: FitSettings, overrides: dict[str, Any]) -> FitSettings:
    """``settings`` with the fields of ``overrides`` replaced (checked again)."""
    return FitSettings(**{**settings.__dict__, **overrides}) if overrides else settings


def with_metrics(result: FitResult, metrics: dict[str, Any], name: str | None = None) -> FitResult:
    """``result`` with ``metrics`` (its JSON) set, and its pack record carrying them (renamed to ``name``)."""
    packed = result.packed
    result.metrics = metrics
    result.packed = PackedMaterial(
        name=name or packed.name,
        coefficients=packed.coefficients,
        eta_i_range=packed.eta_i_range,
        source=packed.source,
        metrics=metrics,
        model=packed.model,
    )
    return result


@dataclass(frozen=True)
class FitProblem:
    """
    What a fit of one kind to ``nk`` over ``eta_i_range`` solves
    (:func:`fit_problem`): the ``settings`` that run, the samples (``mu``,
    ``eta``, ``weights``) and the spectral reference ``target`` there,
    ``rows`` (a scene's set of eta_i, else None), the data's ``coverage`` and
    ``warnings``, and the seconds the reference took. Fits of other degrees
    share it (:meth:`with_degree`).
    """

    kind: FitKind
    nk: SpectralNK
    eta_i_range: tuple[float, float]
    settings: FitSettings
    mu: np.ndarray
    eta: np.ndarray
    weights: np.ndarray | None
    target: np.ndarray
    rows: np.ndarray | None
    coverage: float
    warnings: tuple[str, ...]
    seconds: float

    def with_degree(self, degree: int) -> "FitProblem":
        """The same problem for a polynomial of ``degree`` (the reference is shared)."""
        return replace(self, settings=settings_with(self.settings, {"degree": degree}))

    @property
    def guarded(self) -> bool:
        """Whether the kind guards its max under these settings (see :attr:`FitKind.guard`)."""
        return self.kind.guard is not None and self.settings.guard_max and self.settings.objective != "rgb"


def fit_problem(
    kind: FitKind, nk: SpectralNK, eta_i_range, settings: FitSettings | None = None, samples=None, **overrides
) -> FitProblem:
    """The :class:`FitProblem` of :func:`fit_spectral` (its arguments): the reference on the samples."""
    t0 = time.perf_counter()
    model = model_kind(kind.name)
    if not model.polynomial:
        overrides.pop("degree", None)
    settings = settings_with(settings or kind.settings, overrides)
    eta_i_range = check_eta_i_range(eta_i_range)
    nodes, _ = spectral_weights(settings.step_nm)
    coverage = resample_nk(nk, nodes, settings.min_coverage).coverage
    # Gaps inside the visible range, isolated outliers (fitting.optics.quality).
    warnings = tuple(check_gaps(nk, settings.max_gap_nm) + outlier_warnings(nk))
    rows = None if samples is None else unique(samples[1])
    if samples is None:
        samples = fit_grid(eta_i_range, settings.mu_samples, settings.eta_samples, settings.grid)
    mu, eta, weights = samples
    target = reference_ACEScg(nk, mu, eta, settings.step_nm, settings.min_coverage)
    return FitProblem(
        kind, nk, eta_i_range, settings, mu, eta, weights, target, rows, coverage, warnings, time.perf_counter() - t0
    )


def solve_problem(problem: FitProblem, **settings) -> FitResult:
    """The kind's solve and float16 quantisation of ``problem`` (no guard); ``settings``: as :attr:`FitKind.solve`'s."""
    s = problem.settings
    return problem.kind.solve(
        problem.target,
        problem.mu,
        problem.eta,
        problem.eta_i_range,
        s.degree,
        s.objective,
        s.max_nfev,
        s.quantise,
        weights=problem.weights,
        irls_rounds=s.irls_rounds,
        **settings,
    )


def guard_problem(problem: FitProblem, result: FitResult) -> FitResult:
    """``result`` (:func:`solve_problem`'s) with its max guarded when :attr:`FitProblem.guarded`, else itself."""
    if not problem.guarded:
        return result
    p = problem
    return p.kind.guard(p.nk, p.target, p.mu, p.eta, p.weights, p.eta_i_range, p.settings, result, rows=p.rows)


def _metrics_dtype(evaluate: bool | str) -> str | None:
    """The arithmetic of the metrics' reference ``evaluate`` asks for (None: no metrics)."""
    if isinstance(evaluate, str):
        if evaluate not in DTYPES:
            raise ValueError(f"`evaluate` must be a bool or one of {', '.join(DTYPES)}, got {evaluate!r}")
        return evaluate
    return "float64" if evaluate else None


def finish_fit(problem: FitProblem, result: FitResult, assess: bool = True, evaluate: bool | str = False) -> FitResult:
    """
    ``result`` with its ``coverage``, ``settings``, ``quality`` and
    ``packed`` record (the citation of the data with the warnings as its
    source) and, with ``evaluate`` (as :func:`fit_spectral`), its metrics; ``assess=False`` leaves out
    the kind's quality (the proof of [0, 1]) and the data's uncertainty, for
    a fit that is scored but not shipped (:func:`finish_fit` again assesses it).
    """
    nk, eta_i_range, settings = problem.nk, problem.eta_i_range, problem.settings
    dtype = _metrics_dtype(evaluate)
    t0 = time.perf_counter()
    result.coverage = problem.coverage
    result.settings = settings
    result.timings["reference"] = problem.seconds
    warnings = list(problem.warnings)
    result.quality = {"warnings": warnings}
    if assess:
        t_quality = time.perf_counter()
        if problem.kind.quality is not None:
            result.quality = problem.kind.quality(result, eta_i_range, warnings)
        # How far gaps and sparse sampling leave the figure uncertain (fitting.fits.fit_quality).
        uncertainty = data_uncertainty(nk, eta_i_range, settings.min_coverage)
        if uncertainty is not None:
            own, warning = uncertainty_warning(
                uncertainty, nk, eta_i_range, model_kind(problem.kind.name).name, result.coefficients_float16
            )
            result.quality["uncertainty"] = {**uncertainty, "fit_delta_E_mean": own}
            if warning is not None:
                result.quality["warnings"] = [*result.quality["warnings"], warning]
        result.timings["quality"] = time.perf_counter() - t_quality
    result.packed = PackedMaterial(
        name=nk.name,
        coefficients=result.coefficients_float16,
        eta_i_range=eta_i_range,
        source=provenance(nk.source, result.quality),
        model=result.model,
    )
    if dtype is not None:
        t_eval = time.perf_counter()
        metrics = evaluate_material(nk, result, min_coverage=settings.min_coverage, dtype=dtype)
        metrics["quality"] = result.quality
        if result.guard is not None:
            metrics["guard"] = result.guard
        with_metrics(result, metrics)
        result.timings["evaluate"] = time.perf_counter() - t_eval
    stages = ("reference", "fit", "quantise", "guard")
    result.timings["total"] = sum(result.timings.get(k, 0.0) for k in stages) + time.perf_counter() - t0
    return result


def fit_spectral(
    kind: FitKind,
    nk: SpectralNK,
    eta_i_range,
    settings: FitSettings | None = None,
    evaluate: bool | str = False,
    samples=None,
    **overrides,
) -> FitResult:
    """
    Fit model kind ``kind`` to the spectral reference of ``nk`` over
    ``eta_i_range``; ``evaluate``: no metrics (False), the metrics (True:
    their 1 nm reference in float64, the definition) or the metrics with
    their reference in the arithmetic named (one of
    :data:`fitting.colour.reference.DTYPES`; ``"float32"``, as the service
    evaluates its fits, is within 0.001 Delta E of float64).

    The reference on the fitting grid of ``settings`` (default
    ``kind.settings``; ``overrides`` replace fields, ``degree`` only for a
    kind with a power axis) comes from the exact Fresnel equations integrated
    to linear ACEScg at ``step_nm``; ``samples``, ``(cos_theta, eta_i,
    weights)``, replace that grid (a scene's own eta_i). ``kind.solve`` fits
    and quantises, ``kind.guard`` guards the max, ``kind.quality`` and the
    data's uncertainty say what the fit can be trusted for: the stages
    :func:`fit_problem`, :func:`solve_problem`, :func:`guard_problem`,
    :func:`finish_fit`.

    Returns
    -------
    FitResult
        With ``packed`` (float16, the citation of ``nk`` as source),
        ``coverage``, ``settings`` (those that ran), ``timings``
        (``reference``, ``fit``, ``quantise``, ``evaluate`` when evaluated,
        ``total``: the whole call) and, when ``evaluate`` is not False, ``metrics``
        and ``error`` (:func:`fitting.fits.evaluate.evaluate_material`).

    Raises
    ------
    ValueError
        For an unknown kind, an invalid domain, setting or ``evaluate``, or
        data covering too little of the visible range.
    """
    t0 = time.perf_counter()
    _metrics_dtype(evaluate)  # refused before the fit
    problem = fit_problem(kind, nk, eta_i_range, settings, samples, **overrides)
    result = finish_fit(problem, guard_problem(problem, solve_problem(problem)), evaluate=evaluate)
    result.timings["total"] = time.perf_counter() - t0
    return result
