"""
Evaluation of a material fit
============================

-   :func:`evaluate_material`: Delta E 2000 of the model and the baselines
    against the 1 nm reference on the paper's 100 x 100 grid.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Sections 4.1 and 4.3.
"""

from __future__ import annotations

from typing import Any

from ..colour.reference import evaluation_grid, reference_ACEScg
from ..domain import DEFAULT_MIN_COVERAGE
from ..models.coated_conductor import coated_conductor_model
from ..optics.nk import SpectralNK
from .metrics import baseline_metrics, error_metrics
from .result import FitResult

__all__ = ["evaluate_material"]


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
