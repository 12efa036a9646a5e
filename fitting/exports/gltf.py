"""
glTF export
===========

A glTF 2.0 asset (JSON, buffers embedded as a base64 data URI) with one
material and a small UV sphere that uses it, so the file opens in any glTF
viewer. The material is metallic (``metallicFactor`` 1), ``roughnessFactor``
the metal's roughness, with a ``KHR_materials_clearcoat`` coat of factor 1
(the coat is there, whole) and the coat's roughness, its index eta_i in the
nested draft ``KHR_materials_clearcoat_ior``; its ``baseColorFactor`` is
fitted so that three.js's ``MeshPhysicalMaterial`` (its metallic base and its
clear coat of fixed index 1.5, layered at the view angle in air) follows the
physical coat of index eta_i on the metal seen from air
(:mod:`fitting.exports.seen_fit`); for a rough metal it follows what three
draws at the metal's roughness under a smooth coat
(:mod:`fitting.exports.gltf_fallback`). At eta_i 1 there is no coat: no
``KHR_materials_clearcoat`` at all. Provenance, with the
full fit id, the service version, the coat index and the working space
(:func:`fitting.exports.naming.identity`), is in the material's and the
asset's ``extras``; the material's name is ``<name>_<id>_<eta>``
(:func:`fitting.exports.naming.element_stem`), unique per fit and coat index.
Its colours are in the export's working space (glTF's own is linear Rec.709:
an ``acescg`` export is for a pipeline that reads the asset's
``extras.coated_fresnel.working_space``).

When the values carry the fit's own model (:attr:`ExportValues.model`), the
material also has ``EXT_materials_coated_conductor``
(:mod:`fitting.exports.gltf_coated`), the metal's model for a viewer that
implements it, composed with the clear coat above, listed in
``extensionsUsed`` only: the base colour is its fallback.

-   :func:`gltf_document`: the asset as JSON text (the buffer a base64 data URI).
-   :func:`glb_document`: the same asset as binary glTF (``.glb``: a JSON
    chunk and a BIN chunk holding the buffer); :func:`glb_bytes` packs any
    asset and buffer so.
-   :func:`gltf_material`: the material of ``values`` and the extensions it uses.
-   :func:`uv_sphere`: the sphere's positions, normals and indices.

References
----------
Khronos (2021). glTF 2.0 Specification; KHR_materials_clearcoat.
"""

from __future__ import annotations

import base64
import json
import struct

import numpy as np

from .gltf_coated import CLEARCOAT_IOR, EXTENSION_NAME, clearcoat_object, coated_conductor_extension
from .gltf_fallback import gltf_seen_delta_E
from .naming import element_stem, identity
from .seen_fit import seen_fidelity
from .values import ExportValues

__all__ = ["MODEL_KIND", "GLTF_COAT_IOR", "gltf_document", "glb_document", "glb_bytes", "gltf_material", "uv_sphere"]

MODEL_KIND = (
    "metallic base colour and clear coat factor, fitted under three.js's clear coat to the coated metal seen from air"
)
GLTF_COAT_IOR = 1.5
"""The index of refraction glTF's KHR_materials_clearcoat assumes."""

_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_FLOAT, _UNSIGNED_SHORT = 5126, 5123
_CHUNK_JSON, _CHUNK_BIN = 0x4E4F534A, 0x004E4942


def uv_sphere(segments: int = 24, rings: int = 12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    A unit UV sphere: float32 positions and normals (V, 3), uint16 triangle
    indices (T * 3,), counter-clockwise seen from outside; no degenerate
    triangles at the poles.
    """
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    normals = np.stack([np.sin(T) * np.cos(P), np.cos(T), -np.sin(T) * np.sin(P)], axis=-1)
    normals = (normals / np.linalg.norm(normals, axis=-1, keepdims=True)).reshape(-1, 3)
    index = np.arange((rings + 1) * (segments + 1)).reshape(rings + 1, segments + 1)
    triangles = []
    for i in range(rings):
        for j in range(segments):
            a, b = index[i, j], index[i, j + 1]
            c, d = index[i + 1, j], index[i + 1, j + 1]
            if i > 0:
                triangles.append((a, c, b))
            if i < rings - 1:
                triangles.append((b, c, d))
    normals = normals.astype(np.float32)
    return normals.copy(), normals, np.asarray(triangles, dtype=np.uint16).ravel()


def _padded(data: bytes) -> bytes:
    return data + b"\0" * (-len(data) % 4)


def gltf_document(values: ExportValues) -> str:
    """The glTF 2.0 asset of ``values`` as JSON text."""
    asset, buffer = _asset(values)
    asset["buffers"] = [
        {
            "byteLength": len(buffer),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(buffer).decode("ascii"),
        }
    ]
    return json.dumps(asset, indent=1) + "\n"


def glb_document(values: ExportValues) -> bytes:
    """
    The glTF 2.0 asset of ``values`` as a GLB (glTF 2.0, 4.4 Binary glTF
    Layout): the 12-byte header, the JSON chunk (padded with spaces) and
    the BIN chunk (padded with zeros), the buffer without a URI.
    """
    asset, buffer = _asset(values)
    return glb_bytes(asset, buffer)


def glb_bytes(asset: dict, buffer: bytes) -> bytes:
    """``asset`` (without ``buffers``) and its one buffer as a GLB (glTF 2.0, 4.4)."""
    asset = {**asset, "buffers": [{"byteLength": len(buffer)}]}
    text = json.dumps(asset, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary = _padded(buffer)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return b"".join(
        [
            struct.pack("<4sII", b"glTF", 2, total),
            struct.pack("<II", len(text), _CHUNK_JSON),
            text,
            struct.pack("<II", len(binary), _CHUNK_BIN),
            binary,
        ]
    )


def gltf_material(values: ExportValues) -> tuple[dict, list[str], dict]:
    """The glTF material of ``values``, the extensions it uses (in order) and the provenance."""
    fidelity = seen_fidelity(values, "gltf")
    provenance = values.provenance(MODEL_KIND, fidelity)
    fitted = values.tools["gltf"]
    coat_on = fitted["coat"]
    if coat_on:
        provenance["clearcoat_ior_assumed_by_gltf"] = GLTF_COAT_IOR
    if coat_on and values.seen_rough_ACEScg is not None:
        dE = gltf_seen_delta_E(
            fitted, values.view_cos, values.eta_i, values.seen_rough_ACEScg, values.roughness, values.working_space
        )
        provenance["delta_E_2000_seen_at_roughness"] = (
            f"mean {dE.mean():.3f}, max {dE.max():.3f} at the metal's roughness "
            f"{values.roughness:g} under a smooth coat (what the values are fitted to)"
        )
    if coat_on and abs(values.eta_i - GLTF_COAT_IOR) > 1e-9:
        provenance["note"] = (
            f"fitted for a coat of index {values.eta_i:g}; glTF renders its clear coat "
            f"with index {GLTF_COAT_IOR:g} unless it reads {CLEARCOAT_IOR}, so the base colour is "
            f"fitted to what the metal under the {values.eta_i:g} coat looks like"
        )
    material, used = _material(values, fitted, coat_on, provenance)
    return material, used, provenance


def sphere_buffer() -> tuple[bytes, list[dict], list[dict]]:
    """The unit sphere's buffer, its buffer views and accessors (positions 0, normals 1, indices 2)."""
    positions, normals, indices = uv_sphere()
    blobs = [positions.tobytes(), normals.tobytes(), indices.tobytes()]
    offsets = np.cumsum([0] + [len(_padded(b)) for b in blobs])
    buffer = b"".join(_padded(b) for b in blobs)
    views = [
        {"buffer": 0, "byteOffset": int(offsets[i]), "byteLength": len(blobs[i]), "target": target}
        for i, target in enumerate((_ARRAY_BUFFER, _ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER))
    ]
    accessors = [
        {
            "bufferView": 0,
            "componentType": _FLOAT,
            "count": len(positions),
            "type": "VEC3",
            "min": positions.min(axis=0).tolist(),
            "max": positions.max(axis=0).tolist(),
        },
        {"bufferView": 1, "componentType": _FLOAT, "count": len(normals), "type": "VEC3"},
        {"bufferView": 2, "componentType": _UNSIGNED_SHORT, "count": len(indices), "type": "SCALAR"},
    ]
    return buffer, views, accessors


def _material(values: ExportValues, fitted: dict, coat_on: bool, provenance: dict) -> tuple[dict, list[str]]:
    material = {
        "name": element_stem(values),
        "pbrMetallicRoughness": {
            "baseColorFactor": [round(float(v), 6) for v in fitted["base_color"]] + [1.0],
            "metallicFactor": 1.0,
            "roughnessFactor": round(values.roughness, 6),
        },
        "extensions": {},
    }
    used = []
    if coat_on:
        material["extensions"]["KHR_materials_clearcoat"] = clearcoat_object(
            values.eta_i, values.coat_roughness, fitted["clearcoat"]
        )
        used += ["KHR_materials_clearcoat", CLEARCOAT_IOR]
    if values.model is not None:
        extension, why_not = coated_conductor_extension(values.model, values.eta_i)
        if extension is None:
            provenance["coated_conductor_extension"] = why_not
        else:
            material["extensions"][EXTENSION_NAME] = extension
            used.append(EXTENSION_NAME)
    if not material["extensions"]:
        del material["extensions"]
    material["extras"] = {"coated_fresnel": {**provenance, **identity(values, with_pack=True)}}
    return material, used


def _asset(values: ExportValues) -> tuple[dict, bytes]:
    """The asset without ``buffers``, and the buffer's bytes."""
    material, used, provenance = gltf_material(values)
    buffer, views, accessors = sphere_buffer()
    asset = {
        "asset": {
            "version": "2.0",
            "generator": provenance["generator"],
            "extras": {"coated_fresnel": provenance},
        },
        **({"extensionsUsed": used} if used else {}),
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "sphere"}],
        "meshes": [
            {
                "name": "sphere",
                "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}],
            }
        ],
        "materials": [material],
        "accessors": accessors,
        "bufferViews": views,
    }
    return asset, buffer
