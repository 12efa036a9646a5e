"""
Scene packs: the results
========================

-   :class:`SceneMaterialResult`: one fitted scene material, compared with
    the general fit, and its report.
-   :class:`SceneResult`: the fitted scene, its pack (binary and JSON) and
    its report with totals.

Record sizes come from the pack format (:func:`fitting.models.pack.material_record_bytes`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..models.kinds import coefficient_count, model_kind
from ..models.pack import PackedMaterial, encode_pack, material_record_bytes, pack_to_json
from .metrics import ErrorMetrics
from .result import FitResult
from .scene_schema import Scene, SceneMaterial

__all__ = ["SceneMaterialResult", "SceneResult"]


@dataclass
class SceneMaterialResult:
    """
    One fitted material of a scene.

    ``packed`` is the scene fit (in the pack), ``general`` the general fit it
    is compared with; ``by_degree`` the Delta E 2000 (mean, max) of each
    candidate degree, ``scene`` and ``general_error`` those of the chosen and
    the general float16 model, ``scene_vs_general`` the Delta E between the
    two models; all on the same evaluation grid. ``choice`` (with a scene's
    ``max_delta_e`` or ``prefer``): the rule, the chosen kind and degree, why,
    and every candidate's Delta E 2000.
    """

    material: SceneMaterial
    packed: PackedMaterial
    fit: FitResult
    general: PackedMaterial
    by_degree: dict[int, ErrorMetrics]
    scene: ErrorMetrics
    general_error: ErrorMetrics
    scene_vs_general: ErrorMetrics
    seconds: float
    choice: dict[str, Any] | None = None

    @property
    def degree(self) -> int:
        return self.packed.degree

    @property
    def bytes(self) -> int:
        return material_record_bytes(self.packed.name, self.packed.source, self.degree, self.packed.model)

    @property
    def general_bytes(self) -> int:
        return material_record_bytes(self.general.name, self.general.source, self.general.degree)

    @property
    def shader_variant(self) -> str:
        """The kind's ``evaluate.frag`` variant: ``rgb_conductor``, ``collapsed``
        (Eq. 1 with constant F0, a, alpha) or ``packed`` (:meth:`fitting.models.kinds.ModelKind.variant`)."""
        return model_kind(self.packed.model).variant(self.degree)

    @property
    def coefficients(self) -> int:
        return coefficient_count(self.packed.model, self.degree)

    def report(self) -> dict[str, Any]:
        return {
            "name": self.packed.name,
            "material": self.material.material,
            "eta_i": self.material.eta_i.to_json(),
            "eta_i_range": list(self.packed.eta_i_range),
            "model": self.packed.model,
            "degree": self.degree,
            "coefficients": self.coefficients,
            "shader_variant": self.shader_variant,
            "bytes": self.bytes,
            "delta_E_2000": self.scene.to_dict(),
            "by_degree": {str(d): v.to_dict() for d, v in self.by_degree.items()},
            "general": {
                "eta_i_range": list(self.general.eta_i_range),
                "degree": self.general.degree,
                "coefficients": 9 * (self.general.degree + 1),
                "bytes": self.general_bytes,
                "delta_E_2000": self.general_error.to_dict(),
            },
            "scene_vs_general_delta_E_2000": self.scene_vs_general.to_dict(),
            "fit": self.fit.summary(),
            "seconds": self.seconds,
            **({"choice": self.choice} if self.choice is not None else {}),
        }


@dataclass
class SceneResult:
    """The fitted scene: one :class:`SceneMaterialResult` per material."""

    scene: Scene
    materials: list[SceneMaterialResult] = field(default_factory=list)

    @property
    def packed(self) -> list[PackedMaterial]:
        return [m.packed for m in self.materials]

    def pack_bytes(self) -> bytes:
        """The scene pack in the binary format."""
        return encode_pack(self.packed)

    def pack_json(self) -> str:
        """The scene pack in its JSON view."""
        return pack_to_json(self.packed)

    def report(self) -> dict[str, Any]:
        """JSON-friendly report: per material and totals."""
        general_pack = encode_pack([m.general for m in self.materials])
        return {
            "scene": self.scene.name,
            "materials": [m.report() for m in self.materials],
            "totals": {
                "pack_bytes": len(self.pack_bytes()),
                "general_pack_bytes": len(general_pack),
                "coefficients": sum(m.coefficients for m in self.materials),
                "general_coefficients": 27 * len(self.materials),
                "delta_E_2000_mean": float(np.mean([m.scene.mean for m in self.materials])),
                "general_delta_E_2000_mean": float(np.mean([m.general_error.mean for m in self.materials])),
            },
        }
