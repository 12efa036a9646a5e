"""
glTF extension EXT_materials_coated_conductor
=============================================

The material extension that carries this project's model itself into a
glTF asset (specification: ``docs/gltf/EXT_materials_coated_conductor/``):
the model kind and its float16 coefficients exactly as the pack stores them
(:func:`fitting.models.pack.material_to_json`): the metal only. The coat it
lies under is glTF's own: ``KHR_materials_clearcoat`` (its factor and
roughness, and their textures) with the coat's index in the draft
``KHR_materials_clearcoat_ior`` nested in it (``clearcoatIor``, default
1.5); no ``KHR_materials_clearcoat``, or a factor of 0, is no coat (the
metal in air, index 1). The asset's base colour is the fallback, and the
extension is listed in ``extensionsUsed`` only, so a viewer without it still
draws the fitted values.

-   :data:`EXTENSION_NAME`, :data:`CLEARCOAT_IOR`, :data:`SCHEMA_PATH`.
-   :func:`coated_conductor_extension`: the extension object of a packed
    material at a coating index, or the reason there is none.
-   :func:`clearcoat_object`: the ``KHR_materials_clearcoat`` object of a
    coat (factor, roughness, index).
-   :func:`coat_of`: the coat a material definition composes the extension with.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics
2024 Short Papers, Eq. 1 and 2.
Khronos (2021). glTF 2.0 Specification, 3.12 Extensions.
"""

from __future__ import annotations

from pathlib import Path

from ..models.kinds import model_kind
from ..models.pack import PackedMaterial, material_to_json

__all__ = [
    "EXTENSION_NAME",
    "CLEARCOAT_IOR",
    "SCHEMA_PATH",
    "coated_conductor_extension",
    "clearcoat_object",
    "coat_of",
]

EXTENSION_NAME = "EXT_materials_coated_conductor"
CLEARCOAT_IOR = "KHR_materials_clearcoat_ior"
"""The draft extension (KhronosGroup/glTF pull request 2530) carrying the coat's index, nested in the clear coat."""
SCHEMA_PATH = (
    Path(__file__).resolve().parents[2]
    / "docs"
    / "gltf"
    / EXTENSION_NAME
    / "schema"
    / f"material.{EXTENSION_NAME}.schema.json"
)
"""The extension's JSON Schema (draft 2020-12)."""

# The coated-conductor kind is defined on its fitted domain only; a coat
# index this far outside it (float32 rounding of the stored range) still
# counts as inside.
_RANGE_SLACK = 1e-6


def coated_conductor_extension(material: PackedMaterial, eta_i: float) -> tuple[dict | None, str | None]:
    """
    The ``EXT_materials_coated_conductor`` object of ``material`` drawn
    under a coat of index ``eta_i`` (written by :func:`clearcoat_object`
    beside it), and ``None``; or ``None`` and why there is none (a
    coated-conductor is only defined for eta_i in its fitted range).

    The object: ``kind`` (``coated-conductor`` or ``rgb-conductor``),
    ``colorSpace`` (``ACEScg``, the coefficients' linear space),
    ``etaIRange`` (the fitted domain), ``degree`` (coated-conductor only),
    ``coefficients`` as :func:`fitting.models.pack.material_to_json` writes
    them (float16 values as JSON numbers, exact).
    """
    lo, hi = material.eta_i_range
    if model_kind(material.model).polynomial and not lo - _RANGE_SLACK <= eta_i <= hi + _RANGE_SLACK:
        return None, (
            f"{EXTENSION_NAME} omitted: the coated-conductor fit is defined for eta_i in "
            f"[{lo:g}, {hi:g}], the export is for {eta_i:g}"
        )
    view = material_to_json(material)
    extension = {
        "kind": view["model"],
        "colorSpace": "ACEScg",
        "etaIRange": [float(lo), float(hi)],
    }
    if "degree" in view:
        extension["degree"] = view["degree"]
    extension["coefficients"] = view["coefficients"]
    return extension, None


def clearcoat_object(eta_i: float, coat_roughness: float, factor: float = 1.0) -> dict:
    """
    The ``KHR_materials_clearcoat`` object of a coat of index ``eta_i`` > 1
    (in the nested ``KHR_materials_clearcoat_ior``), perceptual roughness
    ``coat_roughness`` and weight ``factor``.
    """
    return {
        "clearcoatFactor": round(float(factor), 6),
        "clearcoatRoughnessFactor": round(float(coat_roughness), 6),
        "extensions": {CLEARCOAT_IOR: {"clearcoatIor": float(eta_i)}},
    }


def coat_of(material: dict) -> tuple[float, float, float]:
    """
    The coat a glTF material definition composes ``EXT_materials_coated_conductor``
    with: (factor, roughness, index). No ``KHR_materials_clearcoat``, or a
    factor of 0, is no coat: (0, 0, 1). The index is ``clearcoatIor`` of the
    nested ``KHR_materials_clearcoat_ior``, 1.5 without it (glTF's).
    """
    clearcoat = (material.get("extensions") or {}).get("KHR_materials_clearcoat")
    if not isinstance(clearcoat, dict):
        return 0.0, 0.0, 1.0
    factor = float(clearcoat.get("clearcoatFactor", 0.0))
    if factor <= 0.0:
        return 0.0, 0.0, 1.0
    ior = ((clearcoat.get("extensions") or {}).get(CLEARCOAT_IOR) or {}).get("clearcoatIor", 1.5)
    return factor, float(clearcoat.get("clearcoatRoughnessFactor", 0.0)), float(ior)
