"""
Scenes
======

``POST /api/v1/scenes``: a pack with only what a scene needs. The body is a
scene description (:mod:`fitting.scene`): the materials a scene uses and, for
each, its coating indices (one eta_i, a set or a range; 1 is uncoated). Each
material is fitted over those eta_i only, with the lowest polynomial degree
that serves it; the answer is the report (per material: degree, bytes and
Delta E 2000 against the general 27-coefficient fit over the same eta_i) and
the pack, as its JSON view and as the binary file in base64.

A ``material`` is a built-in conductor or the id of a saved material; ``nk``
gives data inline. The fit runs in the service's fitting pool (bounded, with
its time limit); the answer is computed from its input alone, so it is not
stored.
"""

from __future__ import annotations

import base64
import json
from typing import Annotated, Any, Literal

from fastapi import APIRouter
from fastapi.concurrency import run_in_threadpool
from pydantic import BaseModel, ConfigDict, Field, model_validator

from fitting.domain import ETA_I_MAX, ETA_I_MIN
from fitting.fits.scene_fit import fit_scene
from fitting.fits.scene_schema import MAX_ETA_I_VALUES, MAX_SCENE_MATERIALS, parse_scene
from fitting.optics.library import LIBRARY_NAMES, library_material
from fitting.optics.nk import SpectralNK

from ...fitting_jobs import measured_nk
from ...models import API_PREFIX, NKData
from ...store import Store
from ..deps import FIT_ERROR_RESPONSES, RunnerDep, StoreDep, WriteAccess, fit_errors

router = APIRouter(prefix=API_PREFIX, tags=["scenes"])

EtaValue = Annotated[float, Field(ge=ETA_I_MIN, le=ETA_I_MAX, allow_inf_nan=False, description="1 is uncoated")]
Name = Annotated[str, Field(min_length=1, max_length=200, pattern=r"\S")]


class EtaRange(BaseModel):
    """A range of coating indices, min <= max."""

    model_config = ConfigDict(extra="forbid")

    min: EtaValue
    max: EtaValue


class SceneMaterialRequest(BaseModel):
    """One material of a scene: ``material`` (built-in or saved id) or ``nk``, and its eta_i."""

    model_config = ConfigDict(extra="forbid")

    name: Name | None = Field(default=None, description="Name in the pack (default: `material`)")
    material: Name | None = Field(
        default=None, description=f"A built-in conductor ({', '.join(LIBRARY_NAMES)}) or a saved material id"
    )
    nk: NKData | None = None
    source: str = Field(default="scene description", max_length=2000,
                        description="Citation of inline `nk`")
    eta_i: EtaValue | Annotated[list[EtaValue], Field(min_length=1, max_length=MAX_ETA_I_VALUES)] | EtaRange

    @model_validator(mode="after")
    def _check_choice(self) -> "SceneMaterialRequest":
        if (self.material is None) == (self.nk is None):
            raise ValueError("give exactly one of `material` and `nk`")
        if self.nk is not None and self.name is None:
            raise ValueError("`name` is required with `nk`")
        return self


class SceneRequest(BaseModel):
    """A scene description (see ``fitting.scene``)."""

    model_config = ConfigDict(extra="forbid")

    name: Name = "scene"
    materials: list[SceneMaterialRequest] = Field(min_length=1, max_length=MAX_SCENE_MATERIALS)
    max_delta_e: float | None = Field(
        default=None, gt=0.0, le=100.0, allow_inf_nan=False,
        description="Each material gets the cheapest model kind and degree whose mean Delta E 2000 "
        "on its eta_i is at most this",
    )
    prefer: Literal["accuracy"] | None = Field(
        default=None, description="Each material gets its most accurate model kind and degree"
    )


class ScenePublic(BaseModel):
    """The scene's report and its pack."""

    scene: str
    materials: list[dict[str, Any]] = Field(
        description="Per material: degree, coefficients, shader_variant, bytes, delta_E_2000, "
        "by_degree, general (the 27-coefficient fit: bytes, delta_E_2000), fit convergence"
    )
    totals: dict[str, Any]
    pack: dict[str, Any] = Field(description="The pack's JSON view (format coated-fresnel-pack)")
    pack_base64: str = Field(description="The binary pack (docs/pack-format.md), base64")


def _resolver(store: Store):
    """Built-in conductors by name, saved materials by id (their stored n, k)."""

    def resolve(material: str) -> SpectralNK:
        if material in LIBRARY_NAMES:
            return library_material(material)
        record = store.latest_fit(material)
        nk = None if record is None else measured_nk(record)
        if nk is None:
            raise ValueError(
                f"`material` must be a built-in conductor ({', '.join(LIBRARY_NAMES)}) "
                f"or the id of a saved material with n, k, got {material!r}"
            )
        return nk

    return resolve


def _inline_scene(request: SceneRequest, store: Store) -> dict[str, Any]:
    """The scene with every material's n, k inline (validated), for the worker."""
    entries = []
    for entry in request.materials:
        view = entry.model_dump(exclude_none=True, exclude={"source", "nk"})
        if entry.nk is not None:
            view["nk"] = {**entry.nk.model_dump(), "source": entry.source}
        entries.append(view)
    options = request.model_dump(include={"max_delta_e", "prefer"}, exclude_none=True)
    scene = parse_scene({"name": request.name, "materials": entries, **options}, _resolver(store))
    return {
        "name": scene.name,
        **options,
        "materials": [
            {
                "name": m.name,
                "eta_i": m.eta_i.to_json(),
                "nk": {"wavelength_nm": m.nk.wavelength_nm.tolist(), "n": m.nk.n.tolist(),
                       "k": m.nk.k.tolist(), "source": m.nk.source},
                "material": m.material,
            }
            for m in scene.materials
        ],
    }


def _scene_job(scene: dict[str, Any]) -> dict[str, Any]:
    """Runs in a fitting worker: fit the scene, return the report and the pack."""
    names = {m["name"]: m.pop("material") for m in scene["materials"]}
    result = fit_scene(parse_scene(scene))
    report = result.report()
    for material in report["materials"]:
        material["material"] = names[material["name"]]
    report["pack"] = json.loads(result.pack_json())
    report["pack_base64"] = base64.b64encode(result.pack_bytes()).decode("ascii")
    return report


@router.post(
    "/scenes", response_model=ScenePublic,
    responses=FIT_ERROR_RESPONSES, dependencies=[WriteAccess],
)
async def create_scene_pack(request: SceneRequest, store: StoreDep, runner: RunnerDep) -> ScenePublic:
    """
    Fit each material of the scene over the eta_i it uses, with the lowest
    polynomial degree that serves it (one eta_i: 9 coefficients), and answer
    the pack with, per material, its bytes and Delta E 2000 against the
    general 27-coefficient fit over the same eta_i.
    """
    with fit_errors():
        scene = await run_in_threadpool(_inline_scene, request, store)
        report = await runner.run(_scene_job, scene)
    return ScenePublic(**report)
