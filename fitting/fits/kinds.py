"""
Fits by model kind
==================

The registry of how each model kind is fitted, beside the registry of the
kinds themselves (:data:`fitting.models.kinds.MODEL_KINDS`): no other module
of the fits compares kind names.

-   :data:`FIT_KINDS`: kind name to :class:`~fitting.fits.pipeline.FitKind`
    (its default settings and its solve).
-   :func:`register_fit_kind`, :func:`unregister_fit_kind`, :func:`fit_kind`.
-   :func:`fit_model`: measured *n*, *k* to a float16 pack material of any
    registered kind, through the one pipeline
    (:func:`fitting.fits.pipeline.fit_spectral`).
-   :func:`evaluate_model`: the metrics of such a fit on the paper's grid.
"""

from __future__ import annotations

from typing import Any

from ..domain import DEFAULT_ETA_I_RANGE, DEFAULT_MIN_COVERAGE
from ..models.kinds import DEFAULT_MODEL, model_kind
from ..optics.nk import SpectralNK
from .evaluate import evaluate_material
from .material import COATED_CONDUCTOR_FIT
from .pipeline import FitKind, fit_spectral
from .result import FitResult
from .rgb_conductor import RGB_CONDUCTOR_FIT
from .settings import FitSettings

__all__ = ["FIT_KINDS", "register_fit_kind", "unregister_fit_kind", "fit_kind", "fit_model", "evaluate_model"]

FIT_KINDS: dict[str, FitKind] = {}
"""The fit of each model kind, by name."""


def register_fit_kind(kind: FitKind) -> FitKind:
    """
    Add ``kind`` to :data:`FIT_KINDS`.

    Raises
    ------
    ValueError
        When its model kind is not registered (:func:`fitting.models.kinds.register_model_kind`)
        or already has a fit.
    """
    if not isinstance(kind, FitKind):
        raise ValueError(f"`kind` must be a FitKind, got {type(kind).__name__}")
    model_kind(kind.name)
    if kind.name in FIT_KINDS:
        raise ValueError(f"model kind {kind.name!r} already has a fit")
    FIT_KINDS[kind.name] = kind
    return kind


def unregister_fit_kind(name: str) -> None:
    """Remove a fit registered by :func:`register_fit_kind` (tests of a toy kind)."""
    FIT_KINDS.pop(name, None)


def fit_kind(model) -> FitKind:
    """The :class:`FitKind` of model kind ``model``; ``ValueError`` for an unknown or unfitted kind."""
    name = model_kind(model).name
    if name not in FIT_KINDS:
        raise ValueError(f"`model` {name!r} has no fit registered")
    return FIT_KINDS[name]


def fit_model(
    nk: SpectralNK,
    eta_i_range=DEFAULT_ETA_I_RANGE,
    model: str = DEFAULT_MODEL,
    settings: FitSettings | None = None,
    evaluate: bool | str = False,
    samples=None,
    **overrides,
) -> FitResult:
    """
    Fit kind ``model`` to ``nk`` over ``eta_i_range`` with
    :func:`fitting.fits.pipeline.fit_spectral`: ``settings`` default to the
    kind's (:attr:`FitKind.settings`), ``overrides`` replace fields
    (``degree`` applies to kinds with a power axis only), ``samples`` replace
    the fitting grid, ``evaluate`` as there. The result's ``model`` and ``packed.model`` name the
    kind, its ``settings`` are those that ran.

    Raises
    ------
    ValueError
        For an unknown kind, an invalid domain or setting, or data covering
        too little of the visible range.
    """
    return fit_spectral(fit_kind(model), nk, eta_i_range, settings, evaluate, samples, **overrides)


def evaluate_model(
    nk: SpectralNK,
    result: FitResult,
    samples: int = 100,
    baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    dtype: str = "float64",
) -> dict[str, Any]:
    """
    :func:`fitting.fits.evaluate.evaluate_material` for a fit of any kind;
    ``dtype``: the arithmetic of the reference.
    """
    return evaluate_material(nk, result, samples, baselines, min_coverage, dtype)


register_fit_kind(COATED_CONDUCTOR_FIT)
register_fit_kind(RGB_CONDUCTOR_FIT)
