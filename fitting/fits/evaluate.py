"""
Evaluation of a material fit
============================

-   :func:`evaluate_errors`: Delta E 2000 of the model and the baselines
    against the 1 nm reference on the paper's 100 x 100 grid, as
    :class:`fitting.fits.metrics.ErrorMetrics`.
-   :func:`evaluate_material`: the same as the JSON a fit carries.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Sections 4.1 and 4.3.
"""

from __future__ import annotations

from typing import Any

from ..colour.reference import evaluation_grid, reference_ACEScg_grid
from ..domain import DEFAULT_MIN_COVERAGE
from ..models.coated_conductor import coated_conductor_model
from ..optics.nk import SpectralNK
from .metrics import ErrorMetrics, baseline_metrics, error_metrics
from .result import FitResult

__all__ = ["evaluate_errors", "evaluate_material"]


def evaluate_errors(
    nk: SpectralNK, result: FitResult, samples: int = 100, baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> dict[str, ErrorMetrics]:
    """
    Delta E 2000 and RMSE against the 1 nm reference on the paper's grid
    (``samples`` x ``samples`` over [0, 1] x the fitted domain), for the
    float16 model (``model_float16``), the float64 fit (``model_float64``)
    and (optionally) the adjusted Lazanyi and Schlick baselines (by name),
    with the breakdown at eta_i = 1, 1.5, 2, 2.5.
    """
    lo, hi = result.eta_i_range
    M, E = evaluation_grid(samples, (lo, hi))
    # The grid form: the same numbers as reference_ACEScg(nk, M, E), faster.
    ref = reference_ACEScg_grid(nk, M[0], E[:, 0], 1.0, min_coverage)
    rows = E[:, 0]
    against = f"spectral reference 1 nm, {samples} x {samples}"
    out = {
        "model_float16": error_metrics(
            ref, coated_conductor_model(M, E, result.coefficients_float16, (lo, hi)), rows, against
        ),
        "model_float64": error_metrics(
            ref, coated_conductor_model(M, E, result.coefficients, (lo, hi)), rows, against
        ),
    }
    if baselines:
        out.update(baseline_metrics(nk, M, E, ref, min_coverage, against))
    return out


def evaluate_material(
    nk: SpectralNK, result: FitResult, samples: int = 100, baselines: bool = True,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> dict[str, Any]:
    """
    :func:`evaluate_errors` as the JSON a fit carries (``FitResult.metrics``,
    the pack, the API): ``grid``, then each result's
    :meth:`~fitting.fits.metrics.ErrorMetrics.to_dict` by name, ``coverage``.
    Sets ``result.error`` to the float16 model's :class:`ErrorMetrics`.
    """
    errors = evaluate_errors(nk, result, samples, baselines, min_coverage)
    result.error = errors["model_float16"]
    out: dict[str, Any] = {"grid": f"{samples}x{samples}"}
    out["model_float16"] = errors.pop("model_float16").to_dict()
    out["model_float64"] = errors.pop("model_float64").to_dict()
    out["coverage"] = result.coverage
    out.update({name: metrics.to_dict() for name, metrics in errors.items()})
    return out
