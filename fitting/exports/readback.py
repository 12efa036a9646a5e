"""
Reading a fit back in
=====================

A file found in an asset library, back to the fit it was made from: a
binary pack, its JSON view, or an export of this project (glTF or GLB,
MaterialX, OpenPBR, Blender script), each carrying the fit's float16 model
as a binary pack of one material (:func:`fitting.exports.naming.carried_pack`).
Every file is checked before it is believed:

-   **checksum**: the pack's CRC-32 (:func:`fitting.models.pack.decode_pack`);
    a GLB's chunk lengths;
-   **version**: the pack's format version; an export's ``service_version``
    must be a version string;
-   **values**: the export's identity (fit id: 32 hex digits; coat index in
    [1, 3]; working space) the same on the document and the material, the
    coat index the document's own coat index (MaterialX ``coat_ior``), the
    glTF extension's coefficients those of the pack.

Nothing in a file is run: a Blender script's constants are read with
:func:`ast.literal_eval`.

-   :data:`MAX_IMPORT_BYTES`.
-   :class:`ReadBack`: what a file holds.
-   :func:`read_fit_file`: reads and checks one file.
"""

from __future__ import annotations

import ast
import base64
import binascii
import re
import struct
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Any

from ..domain import check_eta_i
from ..models.pack import PACK_MAGIC, PackedMaterial, decode_pack, material_from_json, pack_from_json
from ..optics.bounded import load_json_bounded
from ._xml import IDENTITY_ATTRIBUTES
from .colour_space import check_working_space
from .gltf_coated import CLEARCOAT_IOR, EXTENSION_NAME, coat_of
from .naming import check_fit_id

__all__ = ["MAX_IMPORT_BYTES", "ReadBack", "read_fit_file"]

MAX_IMPORT_BYTES = 16 * 1024 * 1024
"""Largest file read (a glTF export with its sphere is about 30 kB)."""

_GLB_MAGIC, _GLB_JSON = b"glTF", 0x4E4F534A
_BLENDER_FIRST_LINE = "# Blender: a coated metal, made by coated-fresnel."
_VERSION = re.compile(r"[0-9A-Za-z.+_-]{1,64}")


@dataclass(frozen=True)
class ReadBack:
    """
    A file read back.

    Attributes
    ----------
    format
        ``binary``, ``json``, ``gltf``, ``glb``, ``mtlx``, ``openpbr`` or ``blender``.
    materials
        The float16 models (:class:`fitting.models.pack.PackedMaterial`), as packed.
    identity
        An export's ``fit_id``, ``fit_id_kind``, ``service_version``,
        ``eta_i``, ``working_space``; for a pack its JSON view's ``fit_id``
        per material when it has one (``fit_ids``), else empty.
    """

    format: str
    materials: list[PackedMaterial]
    identity: dict = field(default_factory=dict)


def _carried(text, where: str) -> PackedMaterial:
    if not isinstance(text, str) or not text:
        raise ValueError(
            f"`file` carries no fit model ({where}): not an export of this service, or one made without its fit"
        )
    try:
        data = base64.b64decode(text.encode("ascii"), validate=True)
    except (binascii.Error, UnicodeEncodeError):
        raise ValueError(f"`file` has a damaged fit model ({where}): not base64") from None
    try:
        materials = decode_pack(data)
    except ValueError as error:
        raise ValueError(f"`file` has a damaged fit model ({where}): {error}") from None
    if len(materials) != 1:
        raise ValueError(f"`file` must carry one fit model ({where}), got {len(materials)}")
    return materials[0]


def _identity(raw: dict, where: str) -> dict:
    """The identity fields of an export, checked."""
    out: dict[str, Any] = {}
    try:
        out["fit_id"] = check_fit_id(raw.get("fit_id"))
        if out["fit_id"] is None:
            raise ValueError("`fit_id` is missing")
        out["fit_id_kind"] = raw.get("fit_id_kind", "stored")
        if out["fit_id_kind"] not in ("stored", "content"):
            raise ValueError(f"`fit_id_kind` must be stored or content, got {out['fit_id_kind']!r}")
        version = raw.get("service_version")
        if not isinstance(version, str) or not _VERSION.fullmatch(version):
            raise ValueError(f"`service_version` must be a version string, got {version!r}")
        out["service_version"] = version
        out["eta_i"] = check_eta_i(float(raw.get("eta_i")))  # type: ignore[arg-type]  # None: TypeError, said below
        out["working_space"] = check_working_space(raw.get("working_space"))
    except (TypeError, ValueError) as error:
        raise ValueError(f"`file` has damaged identity ({where}): {error}") from None
    return out


def _gltf(asset, format: str) -> ReadBack:
    if not isinstance(asset, dict) or not isinstance(asset.get("materials"), list) or not asset["materials"]:
        raise ValueError("`file` is a glTF asset without materials")
    material = asset["materials"][0]
    info = ((material.get("extras") or {}).get("coated_fresnel")) if isinstance(material, dict) else None
    if not isinstance(info, dict):
        raise ValueError("`file` is a glTF asset without this service's extras (materials[0].extras.coated_fresnel)")
    identity = _identity(info, "materials[0].extras.coated_fresnel")
    model = _carried(info.get("pack"), "materials[0].extras.coated_fresnel.pack")
    extension = (material.get("extensions") or {}).get(EXTENSION_NAME)
    if extension is not None:
        try:
            carried = material_from_json(
                {
                    "name": model.name,
                    "model": extension["kind"],
                    "eta_i_range": extension["etaIRange"],
                    "coefficients": extension["coefficients"],
                    **({"degree": extension["degree"]} if "degree" in extension else {}),
                }
            )
        except (KeyError, TypeError, ValueError) as error:
            raise ValueError(f"`file` has a damaged {EXTENSION_NAME}: {error}") from None
        if carried.model != model.model or carried.coefficients.tobytes() != model.coefficients.tobytes():
            raise ValueError(f"`file` is inconsistent: {EXTENSION_NAME}'s coefficients are not the fit model's")
        try:
            eta = coat_of(material)[2]
        except (AttributeError, TypeError, ValueError) as error:
            raise ValueError(f"`file` has a damaged KHR_materials_clearcoat: {error}") from None
        if abs(eta - identity["eta_i"]) > 1e-9:
            raise ValueError(
                f"`file` is inconsistent: the coat index {EXTENSION_NAME} is drawn under "
                f"(KHR_materials_clearcoat, {CLEARCOAT_IOR}) is not the export's eta_i"
            )
    return ReadBack(format, [model], identity)


def _glb(data: bytes) -> ReadBack:
    if len(data) < 20:
        raise ValueError(f"`file` is a truncated GLB: {len(data)} bytes")
    _, version, length = struct.unpack_from("<4sII", data)
    if version != 2:
        raise ValueError(f"`file` is a GLB of version {version}, only 2 is read")
    if length != len(data):
        raise ValueError(f"`file` is a damaged GLB: the header says {length} bytes, got {len(data)}")
    chunk_length, chunk_type = struct.unpack_from("<II", data, 12)
    if chunk_type != _GLB_JSON or 20 + chunk_length > len(data):
        raise ValueError("`file` is a damaged GLB: its first chunk is not a whole JSON chunk")
    return _gltf(_json(data[20 : 20 + chunk_length]), "glb")


def _materialx(text: str) -> ReadBack:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as error:
        raise ValueError(f"`file` is not well-formed XML: {error}") from None
    if root.tag != "materialx":
        raise ValueError(f"`file` is XML but not MaterialX: root <{root.tag}>")
    materials = root.findall("surfacematerial")
    if len(materials) != 1:
        raise ValueError(f"`file` must hold one surfacematerial, got {len(materials)}")
    keys = {attribute: key for key, attribute in IDENTITY_ATTRIBUTES.items()}
    found = {keys[a]: v for a, v in root.attrib.items() if a in keys}
    on_material = {keys[a]: v for a, v in materials[0].attrib.items() if a in keys}
    if found != on_material:
        differing = sorted(k for k in set(found) | set(on_material) if found.get(k) != on_material.get(k))
        raise ValueError(f"`file` is inconsistent: the document and the material differ in {', '.join(differing)}")
    identity = _identity(found, "MaterialX attributes")
    if root.get("colorspace") != identity["working_space"]:
        raise ValueError(
            f"`file` is inconsistent: colorspace {root.get('colorspace')!r} is not the "
            f"export's working space {identity['working_space']!r}"
        )
    model = _carried(found.get("pack"), IDENTITY_ATTRIBUTES["pack"])
    shaders = [
        node
        for node in root
        if node.tag not in ("nodedef", "nodegraph", "surfacematerial") and node.get("type") == "surfaceshader"
    ]
    coat = [i for shader in shaders for i in shader.findall("input") if i.get("name") == "coat_ior"]
    if coat and abs(float(coat[0].get("value", "nan")) - identity["eta_i"]) > 5e-6 * identity["eta_i"]:
        raise ValueError(
            f"`file` is inconsistent: its coat_ior {coat[0].get('value')} is not the "
            f"export's eta_i {identity['eta_i']:g}"
        )
    openpbr = any(shader.tag == "open_pbr_surface" for shader in shaders)
    return ReadBack("openpbr" if openpbr else "mtlx", [model], identity)


def _blender(text: str) -> ReadBack:
    constants = {}
    try:
        tree = ast.parse(text)
    except SyntaxError as error:
        raise ValueError(f"`file` is a damaged Blender script: {error.msg} at line {error.lineno}") from None
    for node in tree.body:
        if (
            isinstance(node, ast.Assign)
            and len(node.targets) == 1
            and isinstance(node.targets[0], ast.Name)
            and node.targets[0].id in ("IDENTITY", "PACK", "ETA_I", "WORKING_SPACE")
        ):
            try:
                constants[node.targets[0].id] = ast.literal_eval(node.value)
            except ValueError:
                raise ValueError(f"`file` has a damaged {node.targets[0].id} (not a literal)") from None
    if "IDENTITY" not in constants or not isinstance(constants["IDENTITY"], dict):
        raise ValueError("`file` is a Blender script without this service's IDENTITY")
    identity = _identity(constants["IDENTITY"], "IDENTITY")
    if constants.get("ETA_I") != identity["eta_i"] or constants.get("WORKING_SPACE") != identity["working_space"]:
        raise ValueError("`file` is inconsistent: ETA_I or WORKING_SPACE is not the IDENTITY's")
    return ReadBack("blender", [_carried(constants.get("PACK"), "PACK")], identity)


def _json(text: str | bytes):
    try:
        return load_json_bounded(text, max_chars=MAX_IMPORT_BYTES)
    except ValueError as error:
        raise ValueError(f"`file`: {error}") from None


def _pack_json(text: str) -> ReadBack:
    view = _json(text)
    if isinstance(view, dict) and "asset" in view:
        return _gltf(view, "gltf")
    try:
        materials = pack_from_json(text)
    except ValueError as error:
        raise ValueError(f"`file` is not a pack's JSON view: {error}") from None
    fit_ids = [
        ((m.get("metrics") or {}).get("fit_id") if isinstance(m, dict) else None)
        for m in (view.get("materials", []) if isinstance(view, dict) else [])
    ]
    for fit_id in fit_ids:
        check_fit_id(fit_id)
    return ReadBack("json", materials, {"fit_ids": fit_ids} if any(fit_ids) else {})


def read_fit_file(data: bytes) -> ReadBack:
    """
    The fit a file holds (see the module docstring for what is read and checked).

    Raises
    ------
    ValueError
        Naming what is wrong: an empty or too large file, an unknown
        format, a checksum mismatch, a pack version not read, damaged or
        inconsistent identity, no fit model carried.
    """
    if not isinstance(data, (bytes, bytearray)):
        raise ValueError(f"`file` must be bytes, got {type(data).__name__}")
    if not data:
        raise ValueError("`file` is empty")
    if len(data) > MAX_IMPORT_BYTES:
        raise ValueError(f"`file` must be at most {MAX_IMPORT_BYTES} bytes, got {len(data)}")
    data = bytes(data)
    if data[:4] == PACK_MAGIC:
        return ReadBack("binary", decode_pack(data))
    if data[:4] == _GLB_MAGIC:
        return _glb(data)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError("`file` is neither a pack, a GLB nor UTF-8 text") from None
    head = text.lstrip()[:200]
    if head.startswith("{"):
        return _pack_json(text)
    if head.startswith("<"):
        return _materialx(text)
    if head.startswith(_BLENDER_FIRST_LINE):
        return _blender(text)
    raise ValueError(
        "`file` is not a pack, its JSON view, a glTF/GLB, a MaterialX document or a Blender script of this service"
    )
