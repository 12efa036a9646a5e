"""
Error metrics
=============

The response mirror of the core's typed error metrics (``ErrorMetrics`` of
the fitting core: Delta E 2000 mean and max, RMSE, per eta_i row, and what
they were measured against), and of the metrics a fit record carries.
The JSON keys are the core's.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, Field

from .common import Mirror, absent

__all__ = [
    "RowError",
    "MaxAt",
    "Figure",
    "DeltaE",
    "CurveError",
    "DataUncertainty",
    "DataQuality",
    "FitDetails",
    "FitMetrics",
]


class RowError(Mirror):
    """Delta E 2000 of one eta_i row."""

    delta_E_mean: float
    delta_E_max: float


class MaxAt(Mirror):
    """Where a maximum Delta E is (``fitting.fits.metrics.MaxAt``)."""

    eta_i: float
    theta_deg: float = Field(description="Angle in the coating, degrees (0 is normal incidence)")


class Figure(Mirror):
    """
    The one figure of a fit (``ErrorMetrics.figure`` of the core): the same
    numbers as the pack JSON's ``metrics.figure`` and the GLSL / HLSL headers.
    """

    against: str = Field(
        description="What it is measured against, in words: 'the measured metal "
        "(1 nm spectral reference), ...' or 'your edited curves ...'"
    )
    delta_E_mean: float
    delta_E_max: float
    max_at: MaxAt | None = absent("Where the max is")


class DeltaE(Mirror):
    """CIE Delta E 2000 against the reference on the scoring grid (``ErrorMetrics``)."""

    delta_E_mean: float
    delta_E_max: float
    rmse: float | None = absent()
    by_eta_i: dict[str, RowError] | None = absent("Nearest row to each of eta_i 1, 1.5, 2, 2.5")
    against: str | None = absent()
    max_at: MaxAt | None = absent("Where the max is")


class CurveError(Mirror):
    """Delta E 2000 of a curve fit at one edited curve's samples."""

    eta_i: float
    delta_E_mean: float
    delta_E_max: float


class DataUncertainty(Mirror):
    """How far the figure can be off for gaps or sparse data (``fitting.fits.fit_quality.data_uncertainty``)."""

    delta_E_mean: float = Field(
        description="Largest mean Delta E 2000 between the reference of the data "
        "as given and of other plausible interpolations of them"
    )
    fit_delta_E_mean: float | None = Field(None, description="The fit's own mean on the same grid")
    widest_gap_nm: list[float]
    samples_inside_visible: int
    parts: dict[str, float] = Field(description="splines, leave_one_out, window_left_out")


class DataQuality(Mirror):
    """What the fit can be trusted for: the data's warnings, the range proof, the uncertainty."""

    warnings: list[str] = Field(
        default_factory=list,
        description="Sparse or gapped data, outliers (named with their wavelength), a model not proven in [0, 1]",
    )
    uncertainty: DataUncertainty | None = absent("Present for gapped (60 nm or more) or sparse data")


class FitDetails(Mirror):
    """Every metric of a fit, as the core gave it."""

    grid: str | None = absent()
    model_float16: DeltaE | None = absent()
    model_float64: DeltaE | None = absent()
    schlick_air: DeltaE | None = absent()
    schlick_exact_F0: DeltaE | None = absent()
    lazanyi_adjusted: DeltaE | None = absent()
    lazanyi_exact_F0: DeltaE | None = absent()
    coverage: float | None = absent()
    figure: Figure | None = absent("The one figure (FitMetrics.figure)")
    by_curve: list[CurveError] | None = absent()
    samples: int | None = absent("Samples a curve fit fitted")
    best_effort: bool | None = absent(
        "True when the refit's evaluation budget ran out and the fit was made to stay in [0, 1]"
    )
    target: DeltaE | None = absent()
    guard: dict[str, Any] | None = absent(
        "What the fit's solve measured itself: the worst-case guard's "
        "candidates (Delta E 2000 on its points) and which it kept"
    )
    quality: DataQuality | None = absent("The data's warnings and uncertainty (n, k fits)")


class FitMetrics(BaseModel):
    """
    The one figure, Delta E 2000 of the float16 model and of adjusted
    Lazanyi, and every detail. An n, k fit's evaluation on the metrics grid
    runs once, after the fit: until it has, ``evaluated`` is false and
    ``figure``, ``grid``, ``model`` and ``lazanyi_adjusted`` are null
    (``details.guard`` holds what the solve measured itself).
    """

    evaluated: bool = Field(
        True,
        description="False while an n, k fit's evaluation on the metrics grid "
        "has not run yet: `figure`, `grid`, `model` and `lazanyi_adjusted` are then null; "
        "`GET /fits/{id}` (or `?metrics=full` on the fit) waits for it",
    )
    figure: Figure | None = Field(
        None,
        description="The fit's figure: what it is measured against, "
        "mean, max and where the max is; the pack JSON and shader headers quote it",
    )
    grid: str | None = None
    model: DeltaE | None = None
    lazanyi_adjusted: DeltaE | None = None
    details: FitDetails = Field(default_factory=FitDetails)
