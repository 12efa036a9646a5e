"""
A grid of coated metals in one glTF asset
=========================================

The sample asset of ``EXT_materials_coated_conductor``
(``docs/gltf/samples/CoatedConductorGrid/``, written by
``benchmarks/coated_conductor_grid.py``): one sphere per metal and coat index,
rows the metals, columns the coat indices, each sphere with its own material
exactly as the single-material glTF export writes it
(:func:`fitting.exports.gltf.gltf_material`: the fitted base colour, the
clear coat with its index in ``KHR_materials_clearcoat_ior`` and the fit's
model in the extension). The spheres share one mesh's accessors.

-   :func:`grid_asset`: the asset (without ``buffers``) and its buffer.
-   :func:`grid_gltf`: the asset as ``.gltf`` JSON text naming a separate ``.bin``.
-   :func:`grid_glb`: the asset as a GLB (:func:`fitting.exports.gltf.glb_bytes`).

References
----------
Khronos (2021). glTF 2.0 Specification. Khronos glTF-Sample-Assets: the
layout of a sample (``glTF/``, ``glTF-Binary/``, ``screenshot/``, ``README.md``).
"""

from __future__ import annotations

import json

from .gltf import gltf_material, glb_bytes, sphere_buffer
from .values import ExportValues

__all__ = ["SPACING", "grid_asset", "grid_gltf", "grid_glb"]

SPACING = 2.5
"""Distance between the spheres' centres (unit spheres)."""


def grid_asset(rows: list[list[ExportValues]], generator: str) -> tuple[dict, bytes]:
    """
    The asset of ``rows`` (each a list of exports, left to right; rows top
    to bottom, in the plane z = 0) without ``buffers``, and its
    buffer. Nodes are named ``<material> eta_i <index>``; ``generator`` is
    the asset's. A ValueError for an empty grid or rows of unequal length.
    """
    if not rows or not rows[0] or any(len(row) != len(rows[0]) for row in rows):
        raise ValueError("`rows` must be a non-empty grid: rows of equal, non-zero length")
    buffer, views, accessors = sphere_buffer()
    materials: list[dict] = []
    meshes: list[dict] = []
    nodes: list[dict] = []
    used: list[str] = []
    for r, row in enumerate(rows):
        for c, values in enumerate(row):
            material, extensions, _ = gltf_material(values)
            used += [name for name in extensions if name not in used]
            index = len(materials)
            materials.append(material)
            meshes.append(
                {
                    "name": material["name"],
                    "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": index}],
                }
            )
            x = (c - (len(row) - 1) / 2) * SPACING
            y = ((len(rows) - 1) / 2 - r) * SPACING
            nodes.append({"name": f"{values.name} eta_i {values.eta_i:g}", "mesh": index, "translation": [x, y, 0.0]})
    asset = {
        "asset": {"version": "2.0", "generator": generator},
        **({"extensionsUsed": used} if used else {}),
        "scene": 0,
        "scenes": [{"name": "grid", "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
    }
    return asset, buffer


def grid_gltf(asset: dict, buffer: bytes, bin_name: str) -> tuple[str, bytes]:
    """The ``.gltf`` JSON text of ``asset`` with its buffer in the file ``bin_name`` (beside it), and the ``.bin``."""
    if "/" in bin_name or "\\" in bin_name or not bin_name.endswith(".bin"):
        raise ValueError(f"`bin_name` must be a file name ending in .bin, got {bin_name!r}")
    document = {**asset, "buffers": [{"byteLength": len(buffer), "uri": bin_name}]}
    return json.dumps(document, indent=1) + "\n", buffer


def grid_glb(asset: dict, buffer: bytes) -> bytes:
    """``asset`` and its buffer as one GLB."""
    return glb_bytes(asset, buffer)
