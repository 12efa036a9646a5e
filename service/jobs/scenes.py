"""
Scene packs
===========

-   :func:`prepare_scene`: the scene of a request, validated and converted
    once: each material resolved (a built-in conductor, a saved material by
    id, or inline n, k) into a :class:`fitting.fits.scene_schema.SceneMaterial`, or, for
    a saved *edited* material, a :class:`StoredModel` (its edits live in its
    stored model, not in the n, k it started from).
-   :func:`scene_pack`: fit it in the pool, one part per material under the
    job's one slot (the parts take turns with other jobs'); the report and
    the pack.

A material measured as n, k is fitted over the eta_i the scene uses with the
kind and degree its rule picks (:func:`fitting.fits.scene_fit.fit_scene_material`). An
edited material is shipped as stored (its degree, coefficients and domain),
and the scene's eta_i must lie in its domain; its report says so
(``from_stored_model``) and its Delta E against itself is 0.
"""

from __future__ import annotations

import asyncio
import base64
import json

from dataclasses import dataclass
from typing import Any

import numpy as np

from fitting.fits.scene_fit import fit_scene_material
from fitting.fits.scene_schema import EtaSpec, SceneMaterial, parse_eta_i, parse_scene
from fitting.models.kinds import model_kind
from fitting.models.pack import (
    PackedMaterial,
    encode_pack,
    material_from_json,
    material_record_bytes,
    pack_to_json,
)
from fitting.optics.catalogue import catalogue_material, resolve_material

from ..runtime import FitRunner
from ..store import Store
from .common import content_address, measured_nk, with_measured_nk

__all__ = ["StoredModel", "PreparedScene", "prepare_scene", "scene_pack"]


@dataclass(frozen=True)
class StoredModel:
    """A saved edited material in a scene: shipped as its stored model."""

    name: str
    material: str
    eta_i: EtaSpec
    packed: PackedMaterial
    fit_id: str


@dataclass(frozen=True)
class PreparedScene:
    """
    A validated scene: its name, its materials in order, its id, and how
    each material's kind and degree is chosen (``max_delta_e`` or ``prefer``,
    :func:`fitting.fits.scene_fit.choose_candidate`).
    """

    name: str
    materials: tuple[SceneMaterial | StoredModel, ...]
    key: str
    max_delta_e: float | None = None
    prefer: str | None = None


def _catalogued(material: str) -> bool:
    """Whether ``material`` names a library conductor (else it may be a saved material's id)."""
    try:
        resolve_material(material)
    except ValueError:
        return False
    return True


def _renumber(error: ValueError, index: int) -> ValueError:
    return ValueError(str(error).replace("materials[0]", f"materials[{index}]"))


def prepare_scene(store: Store, scene: dict[str, Any]) -> PreparedScene:
    """
    ``scene`` (``{"name", "materials": [...]}``, entries as
    :func:`fitting.fits.scene_schema.parse_scene` reads them, inline ``nk`` with its
    ``source``) resolved against the library and ``store``. Runs in a
    thread (it reads the store).

    Raises
    ------
    ValueError
        Naming the entry and the rule.
    """
    name = scene["name"]
    options = {key: scene[key] for key in ("max_delta_e", "prefer") if scene.get(key) is not None}
    materials: list[SceneMaterial | StoredModel] = []
    seen: set[str] = set()
    used_fits: list[str] = []

    def resolve(material: str):
        if _catalogued(material):
            return catalogue_material(material)
        record = with_measured_nk(store, store.latest_fit(material))
        nk = None if record is None else measured_nk(record)
        if nk is None:
            raise ValueError(
                "`material` must be a library conductor (a name such as gold, a symbol such as Au, "
                f"or an id) or the id of a saved material, got {material[:80]!r}"
            )
        used_fits.append(record.id)
        return nk

    for i, entry in enumerate(scene["materials"]):
        where = f"materials[{i}]"
        entry_name = entry.get("name", entry.get("material"))
        if entry_name in seen:
            raise ValueError(f"`{where}.name` {entry_name!r} is used twice; names in a pack are unique")
        seen.add(entry_name)
        material = entry.get("material")
        record = None
        if material is not None and not _catalogued(material):
            record = with_measured_nk(store, store.latest_fit(material))
        if record is not None and record.kind == "curves":
            eta = parse_eta_i(entry["eta_i"], f"{where}.eta_i")
            packed = material_from_json(record.material)
            lo, hi = packed.eta_i_range
            if not (np.float32(lo) <= np.float32(eta.domain[0]) and np.float32(eta.domain[1]) <= np.float32(hi)):
                raise ValueError(
                    f"`{where}.eta_i` must lie in the domain [{lo:g}, {hi:g}] of the edited "
                    f"material {material!r}, got [{eta.domain[0]:g}, {eta.domain[1]:g}]"
                )
            stored = PackedMaterial(
                entry_name, packed.coefficients, packed.eta_i_range, source=packed.source, model=packed.model
            )
            materials.append(StoredModel(entry_name, material, eta, stored, record.id))
            used_fits.append(record.id)
            continue
        try:
            (parsed,) = parse_scene({"name": name, "materials": [entry], **options}, resolve).materials
        except ValueError as error:
            raise _renumber(error, i) from None
        materials.append(parsed)
    key = content_address("scene", scene, used_fits)
    return PreparedScene(name, tuple(materials), key, options.get("max_delta_e"), options.get("prefer"))


def _stored_model_report(entry: StoredModel) -> dict[str, Any]:
    packed = entry.packed
    bytes_ = material_record_bytes(packed.name, packed.source, packed.degree, packed.model)
    kind = model_kind(packed.model)
    zero = {"mean": 0.0, "max": 0.0}
    return {
        "name": packed.name,
        "material": entry.material,
        "eta_i": entry.eta_i.to_json(),
        "eta_i_range": list(packed.eta_i_range),
        "degree": packed.degree,
        "coefficients": kind.count(packed.degree),
        "shader_variant": kind.variant(packed.degree),
        "bytes": bytes_,
        "delta_E_2000": zero,
        "by_degree": {str(packed.degree): zero},
        "general": {
            "eta_i_range": list(packed.eta_i_range),
            "degree": packed.degree,
            "coefficients": kind.count(packed.degree),
            "bytes": bytes_,
            "delta_E_2000": zero,
        },
        "scene_vs_general_delta_E_2000": zero,
        "fit": {"from_stored_model": True, "fit_id": entry.fit_id},
        "seconds": 0.0,
    }


def _material_part(entry: SceneMaterial, max_delta_e, prefer) -> tuple[dict[str, Any], Any, Any]:
    """Runs in a fitting worker: one material of a scene (its report, its packed and general models)."""
    try:
        result = fit_scene_material(entry, None, max_delta_e, prefer)
    except ValueError as error:
        raise ValueError(f"material {entry.name!r}: {error}") from None
    return result.report(), result.packed, result.general


def _scene_report(scene: PreparedScene, parts: list[tuple[dict[str, Any], Any, Any]]) -> dict[str, Any]:
    """The report and pack of ``scene`` from its materials' parts, in the scene's order."""
    reports, packed, general = (list(column) for column in zip(*parts))
    pack = encode_pack(packed)
    return {
        "scene": scene.name,
        "materials": reports,
        "totals": {
            "pack_bytes": len(pack),
            "general_pack_bytes": len(encode_pack(general)),
            "coefficients": sum(r["coefficients"] for r in reports),
            "general_coefficients": 27 * len(reports),
            "delta_E_2000_mean": float(np.mean([r["delta_E_2000"]["mean"] for r in reports])),
            "general_delta_E_2000_mean": float(np.mean([r["general"]["delta_E_2000"]["mean"] for r in reports])),
        },
        "pack": json.loads(pack_to_json(packed)),
        "pack_base64": base64.b64encode(pack).decode("ascii"),
    }


ETA_COST_S = 0.03
"""Estimated worker seconds of one part of a scene, a material at one of its eta_i (64 x 32 took 55 s)."""


def scene_parts(scene: PreparedScene) -> int:
    """The parts of ``scene``: each fitted material times the eta_i rows it is fitted and scored at."""
    return sum(len(entry.eta_i.evaluation_eta_i()) for entry in scene.materials if not isinstance(entry, StoredModel))


def check_scene_cost(scene: PreparedScene, runner: FitRunner) -> None:
    """ValueError (422) naming the limit for a scene whose estimated fitting cannot end within its time limit."""
    parts = scene_parts(scene)
    budget_s = runner.timeout_s * runner.workers
    if parts * ETA_COST_S > budget_s:
        raise ValueError(
            f"the scene has {parts} parts (materials x eta_i), about {parts * ETA_COST_S:.0f} s of fitting, more "
            f"than one request may use: {budget_s:g} s (COATED_FIT_TIMEOUT_S x COATED_FIT_WORKERS); split it"
        )


async def _scene_parts(scene: PreparedScene, runner: FitRunner) -> list[tuple[dict[str, Any], Any, Any]]:
    """
    Every material of ``scene`` as a part of its own under the job's one
    slot: parts take turns with other jobs' parts (a large scene does not
    hold a worker for its whole length, and each part has the CPU-time
    limit), and run side by side on idle workers. The first failure cancels
    the parts still running or waiting, so their workers are freed at once.
    """
    tasks: dict[int, asyncio.Future] = {}
    parts: list[Any] = []
    for index, entry in enumerate(scene.materials):
        if isinstance(entry, StoredModel):
            parts.append((_stored_model_report(entry), entry.packed, entry.packed))
        else:
            parts.append(None)
            cost_s = ETA_COST_S * len(entry.eta_i.evaluation_eta_i())
            tasks[index] = asyncio.ensure_future(
                runner.submit(_material_part, entry, scene.max_delta_e, scene.prefer, cost_s=cost_s)
            )
    try:
        done = await asyncio.gather(*tasks.values())
    except BaseException:
        for task in tasks.values():
            task.cancel()
        await asyncio.gather(*tasks.values(), return_exceptions=True)
        raise
    for index, part in zip(tasks, done):
        parts[index] = part
    return parts


async def scene_pack(scene: PreparedScene, runner: FitRunner) -> dict[str, Any]:
    """The report and pack of ``scene`` (cancelled when no request waits for it any more); 422 past its cost."""
    check_scene_cost(scene, runner)

    async def make() -> dict[str, Any]:
        async with runner.slot(scene_parts(scene) * ETA_COST_S):  # its CPU budget follows its parts
            parts = await _scene_parts(scene, runner)
        return _scene_report(scene, parts)

    return await runner.once(scene.key, make)
