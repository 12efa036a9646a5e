"""
Scene packs
===========

Requests :class:`SceneRequest` (with :class:`SceneMaterialRequest`,
:class:`EtaRange`); response :class:`ScenePublic`, its report typed
(:class:`SceneMaterialReport`, :class:`SceneTotals`) with the core's keys.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from fitting.fits.scene_schema import MAX_ETA_I_VALUES, MAX_SCENE_MATERIALS

from .common import ETA_I_LIMITS, Mirror, RequestModel
from .fits import NKData

__all__ = [
    "EtaRange",
    "SceneMaterialRequest",
    "SceneRequest",
    "SceneError",
    "SceneMaterialReport",
    "SceneTotals",
    "ScenePublic",
]

EtaValue = Annotated[
    float, Field(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False, strict=True, description="1 is uncoated")
]
Name = Annotated[str, Field(min_length=1, max_length=200, pattern=r"\S")]


class EtaRange(RequestModel):
    """A range of coating indices, min <= max."""

    model_config = ConfigDict(extra="forbid")

    min: EtaValue
    max: EtaValue


class SceneMaterialRequest(RequestModel):
    """One material of a scene: ``material`` (built-in or saved id) or ``nk``, and its eta_i."""

    model_config = ConfigDict(extra="forbid")

    name: Name | None = Field(default=None, description="Name in the pack (default: `material`)")
    material: Name | None = Field(
        default=None, description="A library conductor (name, symbol or id, e.g. gold, Au) or a saved material id"
    )
    nk: NKData | None = None
    source: str = Field(default="scene description", max_length=2000, description="Citation of inline `nk`")
    eta_i: EtaValue | Annotated[list[EtaValue], Field(min_length=1, max_length=MAX_ETA_I_VALUES)] | EtaRange

    @model_validator(mode="after")
    def _check_choice(self) -> "SceneMaterialRequest":
        if (self.material is None) == (self.nk is None):
            raise ValueError("give exactly one of `material` and `nk`")
        if self.nk is not None and self.name is None:
            raise ValueError("`name` is required with `nk`")
        return self

    def entry(self) -> dict[str, Any]:
        """The entry as :func:`fitting.fits.scene_schema.parse_scene` reads it (inline n, k with its source)."""
        view = self.model_dump(exclude_none=True, exclude={"source", "nk"})
        if self.nk is not None:
            view["nk"] = {**self.nk.model_dump(), "source": self.source}
        return view


class SceneRequest(RequestModel):
    """A scene description (see ``fitting.fits.scene_schema``)."""

    model_config = ConfigDict(extra="forbid")

    name: Name = "scene"
    materials: list[SceneMaterialRequest] = Field(min_length=1, max_length=MAX_SCENE_MATERIALS, fail_fast=True)
    max_delta_e: float | None = Field(
        default=None,
        gt=0.0,
        le=100.0,
        allow_inf_nan=False,
        description="Each material gets the cheapest model kind and degree whose mean Delta E 2000 "
        "on its eta_i is at most this",
    )
    prefer: Literal["accuracy"] | None = Field(
        default=None, description="Each material gets its most accurate model kind and degree"
    )

    def scene(self) -> dict[str, Any]:
        options = self.model_dump(include={"max_delta_e", "prefer"}, exclude_none=True)
        return {"name": self.name, "materials": [m.entry() for m in self.materials], **options}


class SceneError(Mirror):
    """Delta E 2000 (mean, max) on the scene's evaluation grid."""

    mean: float
    max: float


class GeneralReport(Mirror):
    eta_i_range: list[float]
    degree: int
    coefficients: int
    bytes: int
    delta_E_2000: SceneError


class SceneMaterialReport(Mirror):
    """One material of the scene: its degree, bytes and errors, against the general fit."""

    name: str
    material: str
    eta_i: Any
    eta_i_range: list[float]
    degree: int
    coefficients: int
    shader_variant: str
    bytes: int
    delta_E_2000: SceneError
    by_degree: dict[str, SceneError]
    general: GeneralReport
    scene_vs_general_delta_E_2000: SceneError
    fit: dict[str, Any]
    seconds: float


class SceneTotals(Mirror):
    pack_bytes: int
    general_pack_bytes: int
    coefficients: int
    general_coefficients: int
    delta_E_2000_mean: float
    general_delta_E_2000_mean: float


class ScenePublic(BaseModel):
    """The scene's report and its pack."""

    scene: str
    materials: list[SceneMaterialReport] = Field(
        description="Per material: degree, coefficients, shader_variant, bytes, delta_E_2000, "
        "by_degree, general (the 27-coefficient fit: bytes, delta_E_2000), fit convergence"
    )
    totals: SceneTotals
    pack: dict[str, Any] = Field(description="The pack's JSON view (format coated-fresnel-pack)")
    pack_base64: str = Field(description="The binary pack (docs/pack-format.md), base64")
