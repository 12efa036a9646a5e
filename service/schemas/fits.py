"""
n, k fits, packs and plotted curves
===================================

Requests :class:`NKData`, :class:`FitRequest`, :class:`PackRequest`;
responses :class:`FitPublic` (its coefficients keyed by the kind's
parameters, :class:`service.schemas.metrics.FitMetrics`, :class:`FitLinks`) and
:class:`CurvesPublic`; :func:`fit_public` is a stored record's view.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from fitting.models.kinds import model_kind

from ..store import FIT_KINDS, FitRecord
from .common import (
    API_PREFIX,
    DEFAULT_ETA_I_RANGE,
    DEFAULT_MODEL,
    DEFAULT_OBJECTIVE,
    DownloadFormat,
    MAX_EXPORT_PACK,
    MAX_NK_SAMPLES,
    PACK_FORMATS,
    EtaI,
    FitId,
    LibraryName,
    WorkingSpace,
    ModelKind,
    Objective,
    RequestModel,
    Text,
)
from .metrics import FitDetails, FitMetrics

__all__ = [
    "NKData",
    "FitRequest",
    "PackRequest",
    "FitLinks",
    "FitPublic",
    "CurvesPublic",
    "CurveFitPublic",
    "fit_public",
]

Wavelength = Annotated[float, Field(gt=0.0, allow_inf_nan=False, strict=True, description="nm")]
IndexN = Annotated[float, Field(gt=0.0, allow_inf_nan=False, strict=True)]
IndexK = Annotated[float, Field(ge=0.0, allow_inf_nan=False, strict=True)]


class NKData(RequestModel):
    """Measured optical constants: wavelength in nm (strictly increasing), n > 0, k >= 0."""

    model_config = ConfigDict(extra="forbid")

    # fail_fast: one error per list, not one per bad item (20,000 booleans).
    wavelength_nm: list[Wavelength] = Field(min_length=2, max_length=MAX_NK_SAMPLES, fail_fast=True)
    n: list[IndexN] = Field(min_length=2, max_length=MAX_NK_SAMPLES, fail_fast=True)
    k: list[IndexK] = Field(min_length=2, max_length=MAX_NK_SAMPLES, fail_fast=True)

    @model_validator(mode="after")
    def _check_table(self) -> "NKData":
        size = len(self.wavelength_nm)
        for label in ("n", "k"):
            if len(getattr(self, label)) != size:
                raise ValueError(
                    f"`{label}` must have one value per wavelength ({size}), got {len(getattr(self, label))}"
                )
        for i in range(1, size):
            if self.wavelength_nm[i] <= self.wavelength_nm[i - 1]:
                rule = "duplicate" if self.wavelength_nm[i] == self.wavelength_nm[i - 1] else "unsorted"
                raise ValueError(
                    f"`wavelength_nm` must be strictly increasing ({rule}): "
                    f"{self.wavelength_nm[i]:g} after {self.wavelength_nm[i - 1]:g} at index {i}"
                )
        return self

    def arrays(self) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
        return tuple(self.wavelength_nm), tuple(self.n), tuple(self.k)


Unit = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False, strict=False)]
RGBColour = Annotated[list[Unit], Field(min_length=3, max_length=3)]


class FitRequest(RequestModel):
    """
    A fit: ``material`` (a built-in conductor), ``nk`` (measured data, with
    a ``name``), or ``f0`` and ``f82`` (a metal given by its F0 and F82 tint
    in air, linear colours of ``space``, with a ``name``), over the
    coating-index domain ``eta_i_range``.
    """

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {"material": "Au"},
                {"material": "Cu", "eta_i_range": [1.2, 1.8], "objective": "de2000"},
                {"material": "Au", "model": "rgb-conductor"},
                {
                    "name": "my gold",
                    "nk": {"wavelength_nm": [350, 600, 850], "n": [1.6, 0.25, 0.2], "k": [1.9, 3.0, 5.4]},
                },
                {"name": "artist gold", "f0": [0.944, 0.776, 0.373], "f82": [0.93, 0.96, 0.99], "space": "lin_rec709"},
            ]
        },
    )

    material: LibraryName | None = None
    name: Text | None = Field(None, description="Display name of inline data")
    source: str = Field("", max_length=2000, description="Citation of inline data")
    nk: NKData | None = None
    f0: RGBColour | None = Field(None, description="F0 in air, linear, [0, 1] per channel of `space`")
    f82: RGBColour | None = Field(None, description="F82 tint in air (OpenPBR specular_color), [0, 1]")
    space: WorkingSpace = Field("lin_rec709", description="lin_rec709 | acescg: the space of `f0`, `f82`")
    eta_i_range: tuple[EtaI, EtaI] = Field(
        DEFAULT_ETA_I_RANGE, description="Coating index domain [lo, hi], 1 <= lo <= hi <= 3"
    )
    objective: Objective = DEFAULT_OBJECTIVE
    model: ModelKind = Field(
        DEFAULT_MODEL,
        description="Model kind: coated-conductor (Vernooij 2024, 27 float16) or rgb-conductor "
        "(exact Fresnel of the per-channel relative index (n + i k) / eta_i, 6 float16)",
    )

    @model_validator(mode="after")
    def _check_choice(self) -> "FitRequest":
        if (self.f0 is None) != (self.f82 is None):
            raise ValueError("give `f0` and `f82` together (a metal given by its F0 and F82 tint)")
        if sum(x is not None for x in (self.material, self.nk, self.f0)) != 1:
            raise ValueError(
                "give exactly one of `material` (a built-in conductor), `nk` (inline data) or `f0` with `f82` (colours)"
            )
        if self.material is not None and self.name is not None:
            raise ValueError("`name` is only for inline `nk` data (a built-in material has its own)")
        lo, hi = self.eta_i_range
        if lo > hi:
            raise ValueError(f"`eta_i_range` must not be empty: lo {lo:g} > hi {hi:g}")
        return self


class PackRequest(RequestModel):
    """Several stored fits in one pack (a scene's materials)."""

    model_config = ConfigDict(extra="forbid")

    fit_ids: list[FitId] = Field(min_length=1, max_length=256)
    format: DownloadFormat = Field(
        "binary",
        description="binary | json | glsl | hlsl, or an export format of `GET /api/v1/domain`'s "
        f"`export_formats` (a zip archive of one file per fit, at most {MAX_EXPORT_PACK} fits)",
    )
    eta_i: EtaI = Field(1.5, description="Coating index of an export, [1, 3]")
    roughness: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = Field(
        0.2, description="The metal's perceptual roughness of an export, [0, 1]"
    )
    coat_roughness: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = Field(
        0.03, description="The coat's perceptual roughness of an export, [0, 1]"
    )
    working_space: WorkingSpace = Field(
        "lin_rec709", description="lin_rec709 | acescg: the space an export is fitted and written in"
    )
    name: Annotated[str, Field(min_length=1, max_length=100, pattern=r"^[A-Za-z0-9._-]+$")] = "materials"

    @model_validator(mode="after")
    def _check_export_size(self) -> "PackRequest":
        if self.format not in PACK_FORMATS and len(self.fit_ids) > MAX_EXPORT_PACK:
            raise ValueError(
                f"`fit_ids` must hold at most {MAX_EXPORT_PACK} fits for an export pack "
                f"({self.format}), got {len(self.fit_ids)}"
            )
        return self


class FitLinks(BaseModel):
    self: str
    pack_binary: str
    pack_json: str
    pack_glsl: str
    pack_hlsl: str
    curves: str


class FitPublic(BaseModel):
    """A stored fit."""

    id: str
    kind: Literal[FIT_KINDS]  # type: ignore[valid-type]
    material_id: str
    name: str
    source: str
    library_material: str | None = None
    base_fit_id: str | None = None
    eta_i_range: tuple[float, float]
    objective: str
    model: ModelKind = DEFAULT_MODEL
    degree: int
    colour_space: Literal["ACEScg"] = "ACEScg"
    coefficients: dict[str, list[list[float]] | list[float]] = Field(
        description=(
            "Float16 coefficients by the kind's parameters (GET /api/v1/domain: model_kinds): per parameter three "
            "rows (R, G, B) of powers (1, t, t^2) for a kind with a power axis, else one value per channel"
        )
    )
    metrics: FitMetrics
    timings: dict[str, float]
    convergence: dict[str, Any]
    coverage: float | None = None
    has_nk: bool
    created_at: float
    links: FitLinks


class CurvesPublic(BaseModel):
    """RGB curves against the angle, linear ACEScg; None where there is no n, k."""

    fit_id: str
    eta_i: float
    colour_space: Literal["ACEScg"] = "ACEScg"
    theta_deg: list[float]
    cos_theta: list[float]
    model: list[list[float]]
    target: list[list[float]] | None = Field(
        None,
        description="What the fit was fitted to at this eta_i: for a curve fit the blended "
        "edited target (or its curve), else the reference",
    )
    reference: list[list[float]] | None = None
    lazanyi_adjusted: list[list[float]] | None = None


class CurveFitPublic(FitPublic):
    """A curve fit, with its curves at one eta_i when the request asked (``curves_eta_i``)."""

    curves: CurvesPublic | None = Field(
        None,
        description="`GET /fits/{id}/curves` of this fit at `curves_eta_i`, in the same answer "
        "(the editor's live refits: one round trip per drag step)",
    )
    restored_from_bin: bool = Field(
        False, description="The material was in the bin: this save (made without `expected_version`) took it out"
    )


def fit_public(record: FitRecord) -> FitPublic:
    """The public view of a stored fit."""
    view = record.material
    base = f"{API_PREFIX}/fits/{record.id}"
    metrics = record.metrics
    return FitPublic(
        id=record.id,
        kind=record.kind,
        material_id=record.material_id,
        name=record.name,
        source=record.source,
        library_material=record.library_material,
        base_fit_id=record.base_fit_id,
        eta_i_range=tuple(view["eta_i_range"]),
        objective=record.objective,
        model=view.get("model", DEFAULT_MODEL),
        degree=view.get("degree", 0),
        # Rows of powers for a kind with a power axis, one value per channel otherwise.
        coefficients={p: view["coefficients"][p] for p in model_kind(view.get("model", DEFAULT_MODEL)).parameters},
        metrics=FitMetrics(
            evaluated=metrics.get("evaluated", True) is not False,
            figure=metrics.get("figure"),
            grid=metrics.get("grid"),
            model=metrics.get("model_float16"),
            lazanyi_adjusted=metrics.get("lazanyi_adjusted"),
            details=FitDetails.model_validate(metrics),
        ),
        timings=record.timings,
        convergence=record.convergence,
        coverage=record.coverage,
        has_nk=record.nk is not None or record.library_material is not None,
        created_at=record.created_at,
        links=FitLinks(
            self=base,
            pack_binary=f"{base}/pack?format=binary",
            pack_json=f"{base}/pack?format=json",
            pack_glsl=f"{base}/pack?format=glsl",
            pack_hlsl=f"{base}/pack?format=hlsl",
            curves=f"{base}/curves?eta_i=1.5&samples=91",
        ),
    )
