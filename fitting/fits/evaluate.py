"""
Evaluation of a material fit
============================

-   :func:`evaluate_errors`: Delta E 2000 of the model and the baselines
    against the 1 nm reference on the paper's 100 x 100 grid, as
    :class:`fitting.fits.metrics.ErrorMetrics`.
-   :func:`grid_models`: a fit of either kind on the grid.
-   :func:`score_on_grid`: the same for any models on the grid (the
    coated-conductor and rgb-conductor fits share it).
-   :func:`evaluate_material`, :func:`metrics_json`: the same as the JSON a
    fit carries.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Sections 4.1 and 4.3.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..colour.reference import evaluation_grid, reference_ACEScg_grid
from ..domain import DEFAULT_MIN_COVERAGE
from ..models.baselines import baselines_ACEScg
from ..models.kinds import model_ACEScg
from ..optics.nk import SpectralNK
from .metrics import AGAINST_MEASURED, ErrorMetrics, grid_metrics
from .result import FitResult

__all__ = ["evaluate_errors", "grid_models", "score_on_grid", "evaluate_material", "metrics_json"]


def evaluate_errors(
    nk: SpectralNK,
    result: FitResult,
    samples: int = 100,
    baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    dtype: str = "float64",
) -> dict[str, ErrorMetrics]:
    """
    Delta E 2000 and RMSE against the 1 nm reference on the paper's grid
    (``samples`` x ``samples`` over [0, 1] x the fitted domain), for the
    float16 model (``model_float16``), the float64 fit (``model_float64``)
    and (optionally) the adjusted Lazanyi and Schlick baselines (by name),
    with the breakdown at eta_i = 1, 1.5, 2, 2.5. ``dtype``: the arithmetic
    of the reference (:func:`fitting.colour.reference.reference_ACEScg_grid`;
    ``float32`` moves Delta E by less than 1e-4).
    """
    M, E = evaluation_grid(samples, result.eta_i_range)
    return score_on_grid(nk, M, E, grid_models(result, M, E), baselines, min_coverage, dtype)


def grid_models(result: FitResult, cos_theta, eta_i) -> dict[str, np.ndarray]:
    """
    The float16 model (``model_float16``) and the float64 fit
    (``model_float64``) of ``result``, of either kind
    (:func:`fitting.models.kinds.model_ACEScg`), on the grid (``cos_theta``,
    ``eta_i``): linear ACEScg, shape ``cos_theta.shape + (3,)``.
    """
    return {
        name: model_ACEScg(result.model, cos_theta, eta_i, coefficients, result.eta_i_range)
        for name, coefficients in (
            ("model_float16", result.coefficients_float16),
            ("model_float64", result.coefficients),
        )
    }


def score_on_grid(
    nk: SpectralNK,
    cos_theta,
    eta_i,
    models,
    baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    dtype: str = "float64",
    reference=None,
) -> dict[str, ErrorMetrics]:
    """
    :func:`fitting.fits.metrics.grid_metrics` of ``models`` (name to (E, M, 3)
    linear ACEScg) and, with ``baselines``, of every baseline, against the
    1 nm reference on the grid (``cos_theta``, ``eta_i``) of
    :func:`fitting.colour.reference.evaluation_grid`; keyed by name, models
    first; ``dtype`` as :func:`evaluate_errors`. ``reference``: that
    reference when already computed (``reference_ACEScg_grid(nk,
    cos_theta[0], eta_i[:, 0], 1.0, min_coverage, dtype)``), so that it can
    be computed beside the fit, which does not need it.
    """
    # The grid form: the same numbers as reference_ACEScg(nk, M, E), faster.
    ref = reference
    if ref is None:
        ref = reference_ACEScg_grid(nk, cos_theta[0], eta_i[:, 0], 1.0, min_coverage, dtype)
    if baselines:
        models = {**models, **baselines_ACEScg(nk, cos_theta, eta_i, 1.0, min_coverage)}
    return grid_metrics(
        ref, models, eta_i[:, 0], f"{AGAINST_MEASURED}, {eta_i.shape[0]} x {eta_i.shape[1]} grid", cos_theta[0]
    )


def evaluate_material(
    nk: SpectralNK,
    result: FitResult,
    samples: int = 100,
    baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    dtype: str = "float64",
) -> dict[str, Any]:
    """
    :func:`evaluate_errors` as the JSON a fit carries (``FitResult.metrics``,
    the pack, the API): ``grid``, ``figure`` (the float16 model's
    :meth:`~fitting.fits.metrics.ErrorMetrics.figure`), then each result's
    :meth:`~fitting.fits.metrics.ErrorMetrics.to_dict` by name, ``coverage``.
    Sets ``result.error`` to the float16 model's :class:`ErrorMetrics`.
    """
    return metrics_json(evaluate_errors(nk, result, samples, baselines, min_coverage, dtype), result, samples)


def metrics_json(errors: dict[str, ErrorMetrics], result: FitResult, samples: int) -> dict[str, Any]:
    """
    The JSON of :func:`evaluate_material` from the ``errors`` of
    :func:`score_on_grid` (``model_float16``, ``model_float64``, baselines);
    sets ``result.error`` to the float16 model's.
    """
    errors = dict(errors)
    result.error = errors["model_float16"]
    out: dict[str, Any] = {"grid": f"{samples}x{samples}", "figure": result.error.figure()}
    out["model_float16"] = errors.pop("model_float16").to_dict()
    out["model_float64"] = errors.pop("model_float64").to_dict()
    out["coverage"] = result.coverage
    out.update({name: metrics.to_dict() for name, metrics in errors.items()})
    if result.quality:  # the data's warnings and, for gaps or sparse data, the uncertainty beside the error
        out["quality"] = result.quality
    return out
