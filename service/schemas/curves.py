"""
Curve fits and error maps
=========================

Requests :class:`CurveIn`, :class:`CurveBaseIn`, :class:`CurveFitRequest`;
response :class:`ErrorMap`.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from fitting.fits.curves import CurveFitSettings
from fitting.fits.curves_input import CURVE_MAX_COUNT, CURVE_MAX_SAMPLES, CURVE_MIN_SAMPLES

from .common import (
    DEFAULT_MODEL,
    FIT_ID_PATTERN,
    EtaI,
    FitId,
    LibraryName,
    MaterialName,
    ModelKind,
    Objective,
    RequestModel,
)
from .fits import NKData

__all__ = ["CurveIn", "CurveBaseIn", "CurveFitRequest", "ErrorMap"]

_DEFAULTS = CurveFitSettings()
CosTheta = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False, strict=True)]
Angle = Annotated[float, Field(ge=0.0, le=90.0, allow_inf_nan=False, strict=True)]
Reflectance = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False, strict=True)]


class CurveIn(RequestModel):
    """
    One RGB reflectance curve at coating index ``eta_i``: linear ACEScg in
    [0, 1] against cos theta in [0, 1] (or the angle in degrees, [0, 90]).
    """

    model_config = ConfigDict(extra="forbid")

    eta_i: EtaI
    cos_theta: list[CosTheta] | None = Field(
        None, min_length=CURVE_MIN_SAMPLES, max_length=CURVE_MAX_SAMPLES, fail_fast=True
    )
    angle_deg: list[Angle] | None = Field(
        None, min_length=CURVE_MIN_SAMPLES, max_length=CURVE_MAX_SAMPLES, fail_fast=True
    )
    rgb: list[tuple[Reflectance, Reflectance, Reflectance]] = Field(
        min_length=CURVE_MIN_SAMPLES,
        max_length=CURVE_MAX_SAMPLES,
        fail_fast=True,
        description="[R, G, B] per sample, linear ACEScg",
    )

    @model_validator(mode="after")
    def _check_samples(self) -> "CurveIn":
        if (self.cos_theta is None) == (self.angle_deg is None):
            raise ValueError("give exactly one of `cos_theta` or `angle_deg`")
        samples = self.cos_theta if self.cos_theta is not None else self.angle_deg
        if len(samples) != len(self.rgb):
            raise ValueError(f"`rgb` must hold one [R, G, B] per sample ({len(samples)}), got {len(self.rgb)}")
        return self

    def as_dict(self) -> dict:
        """The curve as :func:`fitting.fits.curves_input.check_curves` reads it."""
        item = {"eta_i": self.eta_i, "rgb": [list(v) for v in self.rgb]}
        if self.cos_theta is not None:
            item["cos_theta"] = list(self.cos_theta)
        else:
            item["angle_deg"] = list(self.angle_deg)
        return item


class CurveBaseIn(RequestModel):
    """The material being edited: exactly one of a built-in name, a stored fit or n, k."""

    model_config = ConfigDict(extra="forbid")

    material: LibraryName | None = None
    fit: Annotated[str, Field(pattern=FIT_ID_PATTERN)] | None = Field(None, description="A stored fit's id")
    nk: NKData | None = Field(None, description="Measured n, k")

    @model_validator(mode="after")
    def _check_choice(self) -> "CurveBaseIn":
        given = [k for k in ("material", "fit", "nk") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("`base` must give exactly one of `material`, `fit` or `nk`")
        return self


class CurveFitRequest(RequestModel):
    """
    Curves to fit, alone (``base`` null: the eta_i dependence is what the
    curves determine) or as edits of ``base`` (each curve replaces the base
    at its eta_i, the change fading over ``blend_width`` in eta_i).
    """

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {
                    "name": "warm gold",
                    "base": {"material": "Au"},
                    "curves": [
                        {
                            "eta_i": 1.5,
                            "angle_deg": [0, 30, 60, 75, 90],
                            "rgb": [
                                [0.9, 0.7, 0.35],
                                [0.9, 0.7, 0.35],
                                [0.88, 0.69, 0.36],
                                [0.85, 0.7, 0.45],
                                [1, 1, 1],
                            ],
                        }
                    ],
                }
            ]
        },
    )

    name: MaterialName = Field(
        "edited",
        description="The material's name (NFC; a visible character, no "
        "bidirectional control, not a built-in material's); refits under one name "
        "are one material",
    )
    base: CurveBaseIn | None = None
    eta_i_range: tuple[EtaI, EtaI] | None = Field(
        None, description="Domain [lo, hi]: default the base fit's, else [1, 2.5]"
    )
    curves: list[CurveIn] = Field(min_length=1, max_length=CURVE_MAX_COUNT)
    objective: Objective = _DEFAULTS.objective
    blend_width: float = Field(_DEFAULTS.blend_width, gt=0.0, le=3.0, allow_inf_nan=False, strict=True)
    model: ModelKind = Field(
        DEFAULT_MODEL,
        description="Model kind of the refit: coated-conductor (Vernooij 2024) or "
        "rgb-conductor (per-channel n, k; always within [0, 1])",
    )
    draft: bool = Field(
        False,
        description="Store the fit without saving it under `name` (the editor's "
        "refits while editing); the same request with false saves it",
    )
    live: bool = Field(
        False,
        description="A live refit while a curve is dragged: one short solve "
        "(fitting.fits.curves.LIVE_SETTINGS) started from `start_fit`, "
        "a draft only; the editor replaces it with a full refit on release",
    )
    start_fit: FitId | None = Field(
        None,
        description="With `live`: the stored fit (of the same kind and "
        "domain) whose coefficients the solve starts from",
    )

    material_id: Annotated[str, Field(pattern=r"^[0-9a-f]{32}$")] | None = Field(
        None,
        description="Save as the next version of this saved edited material (its `id` in "
        "`GET /materials`; the editor sends the material it opened, so a renamed "
        "material keeps its history). Unset: the material called `name` now, else a "
        "new one; 409 when another material is called `name`",
    )
    expected_version: int | None = Field(
        None,
        ge=0,
        le=2**62,
        strict=True,
        description="Save only if the material `name` is at this version now (0: not saved yet; the "
        "`version` of `GET /materials/{id}`); else 409, nothing saved. Unset: the save "
        "becomes the next version whatever came before",
    )

    @model_validator(mode="after")
    def _check_range(self) -> "CurveFitRequest":
        if self.eta_i_range is not None and self.eta_i_range[0] > self.eta_i_range[1]:
            lo, hi = self.eta_i_range
            raise ValueError(f"`eta_i_range` must not be empty: lo {lo:g} > hi {hi:g}")
        if self.live and not self.draft:
            raise ValueError("`live` refits are drafts: set `draft` to true (a live refit is never saved)")
        if self.expected_version is not None and self.draft:
            raise ValueError("`expected_version` is for saves: a draft is not saved under `name`")
        if self.start_fit is not None and not self.live:
            raise ValueError("`start_fit` is for `live` refits only")
        return self


class ErrorMap(BaseModel):
    """Delta E 2000 of a fit's float16 model over (eta_i, angle) against its target."""

    fit_id: str
    against: Literal["reference", "edited target", "curves"]
    theta_deg: list[float]
    eta_i: list[float]
    delta_E: list[list[float]] = Field(description="[eta_i row][angle column]")
    delta_E_mean: float
    delta_E_max: float
