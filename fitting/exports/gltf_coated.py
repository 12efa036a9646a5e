"""
glTF extension EXT_materials_coated_conductor
=============================================

The material extension that carries this project's model itself into a
glTF asset (specification: ``docs/gltf/EXT_materials_coated_conductor/``):
the model kind and its float16 coefficients exactly as the pack stores them
(:func:`fitting.models.pack.material_to_json`), the coating index the
material is drawn with, and the coat's roughness. The asset keeps its
fallback (Schlick base colour and ``KHR_materials_clearcoat``) beside it and
lists the extension in ``extensionsUsed`` only, so a viewer without it still
draws the fitted values.

-   :data:`EXTENSION_NAME`, :data:`SCHEMA_PATH`.
-   :func:`coated_conductor_extension`: the extension object of a packed
    material at a coating index, or the reason there is none.

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

__all__ = ["EXTENSION_NAME", "SCHEMA_PATH", "coated_conductor_extension"]

EXTENSION_NAME = "EXT_materials_coated_conductor"
SCHEMA_PATH = (
    Path(__file__).resolve().parents[2] / "docs" / "gltf" / EXTENSION_NAME / "schema"
    / f"material.{EXTENSION_NAME}.schema.json"
)
"""The extension's JSON Schema (draft 2020-12)."""

# The coated-conductor kind is defined on its fitted domain only; a coat
# index this far outside it (float32 rounding of the stored range) still
# counts as inside.
_RANGE_SLACK = 1e-6


def coated_conductor_extension(
    material: PackedMaterial, eta_i: float, coat_roughness: float
) -> tuple[dict | None, str | None]:
    """
    The ``EXT_materials_coated_conductor`` object of ``material`` drawn
    under a coat of index ``eta_i`` with perceptual roughness
    ``coat_roughness``, and ``None``; or ``None`` and why there is none (a
    coated-conductor is only defined for eta_i in its fitted range).

    The object: ``kind`` (``coated-conductor`` or ``rgb-conductor``),
    ``colorSpace`` (``ACEScg``, the coefficients' linear space),
    ``etaIRange`` (the fitted domain), ``degree`` (coated-conductor only),
    ``coefficients`` as :func:`fitting.models.pack.material_to_json` writes
    them (float16 values as JSON numbers, exact), ``coatIor`` and
    ``coatRoughnessFactor``.
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
    extension["coatIor"] = float(eta_i)
    extension["coatRoughnessFactor"] = round(float(coat_roughness), 6)
    return extension, None
