"""
Error metrics
=============

The response mirror of the core's typed error metrics (``ErrorMetrics`` of
the fitting core: Delta E 2000 mean and max, RMSE, per eta_i row, and what
they were measured against), and of the metrics a fit record carries.
The JSON keys are the core's.
"""

from __future__ import annotations

from pydantic import BaseModel, Field

from .common import Mirror

__all__ = ["RowError", "DeltaE", "CurveError", "FitDetails", "FitMetrics"]


class RowError(Mirror):
    """Delta E 2000 of one eta_i row."""

    delta_E_mean: float
    delta_E_max: float


class DeltaE(Mirror):
    """CIE Delta E 2000 against the reference on the scoring grid (``ErrorMetrics``)."""

    delta_E_mean: float
    delta_E_max: float
    rmse: float | None = None
    by_eta_i: dict[str, RowError] | None = Field(None, description="Nearest row to each of eta_i 1, 1.5, 2, 2.5")
    against: str | None = None


class CurveError(Mirror):
    """Delta E 2000 of a curve fit at one edited curve's samples."""

    eta_i: float
    delta_E_mean: float
    delta_E_max: float


class FitDetails(Mirror):
    """Every metric of a fit, as the core gave it."""

    grid: str | None = None
    model_float16: DeltaE | None = None
    model_float64: DeltaE | None = None
    schlick_air: DeltaE | None = None
    schlick_exact_F0: DeltaE | None = None
    lazanyi_adjusted: DeltaE | None = None
    lazanyi_exact_F0: DeltaE | None = None
    coverage: float | None = None
    by_curve: list[CurveError] | None = None
    fitted_samples: int | None = None
    target: DeltaE | None = None


class FitMetrics(BaseModel):
    """Delta E 2000 of the float16 model and of adjusted Lazanyi, and every detail."""

    grid: str | None = None
    model: DeltaE | None = None
    lazanyi_adjusted: DeltaE | None = None
    details: FitDetails = Field(default_factory=FitDetails)
