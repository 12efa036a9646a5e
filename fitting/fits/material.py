"""
Material fits
=============

-   :func:`fit_material`: from measured *n*, *k* to a float16
    :class:`fitting.models.pack.PackedMaterial`, with timings and, on
    request, metrics (:func:`fitting.fits.evaluate.evaluate_material`).

The pipeline: the spectral reference (:mod:`fitting.colour.reference`) on
the fitting grid (:func:`fitting.fits.settings.fit_grid`), the solve and the
quantisation (:func:`fitting.fits.solver.fit_coefficients`), the pack: the
pipeline of :mod:`fitting.fits.pipeline`, with this kind's
:data:`COATED_CONDUCTOR_FIT`.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

from ..domain import DEFAULT_ETA_I_RANGE
from ..models.kinds import DEFAULT_MODEL
from ..optics.nk import SpectralNK
from .pipeline import FitKind, fit_spectral
from .result import FitResult
from .settings import FitSettings
from .solver import fit_coefficients
from .fit_quality import fit_quality
from .guarded import guarded_fit
from .worst_case import guard_reference

__all__ = ["COATED_CONDUCTOR_FIT", "fit_material"]


def _guard(nk, target, mu, eta, weights, eta_i_range, settings, mean_fit: FitResult, rows=None) -> FitResult:
    """The max guarded against the paper's method on a subsample of the scoring grid (at ``rows``: a scene's set)."""
    guard_mu, guard_eta, guard_target = guard_reference(nk, eta_i_range, settings.min_coverage, rows=rows)
    return guarded_fit(
        target,
        mu,
        eta,
        eta_i_range,
        settings.degree,
        settings.objective,
        settings.max_nfev,
        settings.quantise,
        weights,
        settings.irls_rounds,
        guard_target,
        guard_mu,
        guard_eta,
        mean_fit=mean_fit,
    )


def _quality(result: FitResult, eta_i_range, warnings) -> dict:
    """The proof of [0, 1] over the whole domain and the data's warnings."""
    return fit_quality(result.coefficients_float16, eta_i_range, warnings)


COATED_CONDUCTOR_FIT = FitKind(
    name=DEFAULT_MODEL, settings=FitSettings(), solve=fit_coefficients, guard=_guard, quality=_quality
)
"""The coated-conductor's fit (:mod:`fitting.fits.pipeline`; registered in :mod:`fitting.fits.kinds`)."""


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
    individual settings (``objective="rgb"``, ``step_nm=1``, ...). The
    pipeline of every kind: :func:`fitting.fits.pipeline.fit_spectral`.

    Returns
    -------
    FitResult
        With ``packed`` (float16 :class:`fitting.models.pack.PackedMaterial`, the
        citation of ``nk`` as source), ``coverage``, ``settings`` and ``timings``
        (``reference``, ``fit``, ``quantise``, ``evaluate``, ``total``); with
        ``metrics`` from :func:`evaluate_material` when ``evaluate`` is true.

    Raises
    ------
    ValueError
        For an invalid domain or setting, or data covering too little of
        the visible range.
    """
    return fit_spectral(COATED_CONDUCTOR_FIT, nk, eta_i_range, settings, evaluate, **overrides)
