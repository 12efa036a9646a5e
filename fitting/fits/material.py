"""
Material fits
=============

-   :func:`fit_material`: from measured *n*, *k* to a float16
    :class:`fitting.models.pack.PackedMaterial`, with timings and, on
    request, metrics (:func:`fitting.fits.evaluate.evaluate_material`).

The pipeline: the spectral reference (:mod:`fitting.colour.reference`) on
the fitting grid (:func:`fitting.fits.settings.fit_grid`), the solve and the
quantisation (:func:`fitting.fits.solver.fit_coefficients`), the pack.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

import time

from ..colour.reference import reference_ACEScg, spectral_weights
from ..domain import DEFAULT_ETA_I_RANGE, check_eta_i_range
from ..models.pack import PackedMaterial
from ..optics.nk import SpectralNK, resample_nk
from .evaluate import evaluate_material
from .guarded import guarded_fit
from .result import FitResult
from .settings import FitSettings, fit_grid
from .solver import fit_coefficients
from .worst_case import guard_reference
from .fit_quality import fit_quality, provenance
from ..optics.quality import check_gaps

__all__ = ["fit_material"]


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
        With ``packed`` (float16 :class:`fitting.models.pack.PackedMaterial`, the
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
    warnings = check_gaps(nk, settings.max_gap_nm)  # issue 21 hook: gaps inside the visible range
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
    if settings.guard_max and settings.objective != "rgb":  # issue 21 hook (rgb is the paper's method itself)
        guard_mu, guard_eta, guard_target = guard_reference(nk, eta_i_range, settings.min_coverage)
        result = guarded_fit(
            target, mu, eta, eta_i_range, settings.degree, settings.objective, settings.max_nfev,
            settings.quantise, weights, settings.irls_rounds, guard_target, guard_mu, guard_eta,
            mean_fit=result,
        )
    result.coverage = coverage
    result.timings["reference"] = t_ref - t0
    result.quality = fit_quality(result.coefficients_float16, eta_i_range, warnings)
    source = provenance(nk.source, result.quality)
    result.packed = PackedMaterial(
        name=nk.name, coefficients=result.coefficients_float16,
        eta_i_range=eta_i_range, source=source,
    )
    result.timings["total"] = time.perf_counter() - t0
    if evaluate:
        result.metrics = evaluate_material(nk, result, min_coverage=settings.min_coverage)
        result.metrics["quality"] = result.quality
        if result.guard is not None:
            result.metrics["guard"] = result.guard
        result.packed = PackedMaterial(
            name=nk.name, coefficients=result.coefficients_float16,
            eta_i_range=eta_i_range, source=source, metrics=result.metrics,
        )
    return result
