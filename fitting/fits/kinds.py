"""
Fits by model kind
==================

-   :func:`fit_model`: measured *n*, *k* to a float16 pack material of any
    kind of :data:`fitting.models.kinds.MODEL_KINDS`, by
    :func:`fitting.fits.material.fit_material` (``coated-conductor``) or
    :func:`fitting.fits.rgb_conductor.fit_rgb_conductor` (``rgb-conductor``).
-   :func:`evaluate_model`: the metrics of such a fit on the paper's grid.
"""

from __future__ import annotations

from typing import Any

from ..domain import DEFAULT_ETA_I_RANGE, DEFAULT_MIN_COVERAGE
from ..models.kinds import DEFAULT_MODEL, check_model
from ..optics.nk import SpectralNK
from .evaluate import evaluate_material
from .material import fit_material
from .result import FitResult
from .rgb_conductor import evaluate_rgb_conductor, fit_rgb_conductor
from .settings import FitSettings

__all__ = ["fit_model", "evaluate_model"]


def fit_model(
    nk: SpectralNK,
    eta_i_range=DEFAULT_ETA_I_RANGE,
    model: str = DEFAULT_MODEL,
    settings: FitSettings | None = None,
    evaluate: bool = False,
    **overrides,
) -> FitResult:
    """
    Fit kind ``model`` to ``nk`` over ``eta_i_range``; ``settings`` and
    ``overrides`` as :func:`fitting.fits.material.fit_material` (``degree`` applies to
    the coated-conductor only). The result's ``model`` and ``packed.model``
    name the kind.

    Raises
    ------
    ValueError
        For an unknown kind, an invalid domain or setting, or data covering
        too little of the visible range.
    """
    if check_model(model) == "rgb-conductor":
        overrides.pop("degree", None)
        return fit_rgb_conductor(nk, eta_i_range, settings, evaluate, **overrides)
    return fit_material(nk, eta_i_range, settings, evaluate, **overrides)


def evaluate_model(
    nk: SpectralNK, result: FitResult, samples: int = 100, baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE, dtype: str = "float64",
) -> dict[str, Any]:
    """
    :func:`fitting.fits.evaluate.evaluate_material` for a fit of either kind;
    ``dtype``: the arithmetic of the reference.
    """
    if result.model == "rgb-conductor":
        return evaluate_rgb_conductor(nk, result, samples, baselines, min_coverage, dtype)
    return evaluate_material(nk, result, samples, baselines, min_coverage, dtype)
