"""
Pack downloads
==============

Stored fits as the files a renderer loads:

-   ``binary``: the documented binary pack (:func:`fitting.pack.encode_pack`).
-   ``json``: its JSON view (:func:`fitting.pack.pack_to_json`).
-   ``glsl``: a ready-to-paste snippet: the project's GLSL function of
    each model kind in the pack (``preview_shaders/glsl/cf_coated_conductor.glsl``,
    ``cf_rgb_conductor.glsl`` and their include, inlined) and per material
    the float16 coefficients as constants and a
    ``cf_material_<name>(NdotV, eta_i)`` function.
-   ``hlsl``: the same for HLSL, with the HLSL functions from
    ``service/templates/cf_coated_conductor.hlsl`` and ``cf_rgb_conductor.hlsl``.
-   with the coated-conductor kind both snippets also carry the split-sum
    lookup ``cf_split_sum_model`` (and the baselines) that reads the LUT of
    ``GET /api/v1/ibl-lut`` (``cf_ibl.glsl``, ``templates/cf_ibl.hlsl``).

The snippet text comes from the template files in ``service/templates/``.

Exports of one fit for one coating index (:mod:`fitting.exports`), made
from the fit's measured n, k, or for a fit of edited curves from its model:

-   ``mtlx``, ``openpbr``: MaterialX documents; ``blender``: a Blender
    Python script; ``gltf``: a glTF 2.0 asset.

-   :data:`PACK_MEDIA_TYPES`: media type and file suffix per format.
-   :data:`EXPORT_MEDIA_TYPES`: the same for the exports.
-   :func:`render_pack`: the bytes of a download.
-   :func:`render_export`: the bytes of an export of one fit.
-   :func:`download_name`: a safe file name for Content-Disposition.
-   :func:`glsl_identifier`: a material name as a GLSL/HLSL identifier.
"""

from __future__ import annotations

import functools
import io
import re
import string
import zipfile
from pathlib import Path

import numpy as np

from fitting.domain import cached_once
from fitting.exports import EXPORT_FORMATS, export_material
from fitting.models.kinds import model_ACEScg
from fitting.models.pack import PackedMaterial, encode_pack, material_from_json, pack_to_json
from preview_shaders.gl import GLSL_DIR

from .jobs.common import FIT_FORMAT_VERSION, measured_nk
from .store import FitRecord

__all__ = [
    "PACK_MEDIA_TYPES", "EXPORT_MEDIA_TYPES", "PACK_CONTENT", "TEMPLATE_DIR", "render_pack",
    "render_export", "render_export_pack", "pack_response", "export_response", "download_name", "unique_names",
    "glsl_identifier", "IBL_LUT_FILENAME", "ibl_lut_file",
]

IBL_LUT_FILENAME = "cf_ibl_lut.cflut"
SPLIT_SUM_FUNCTIONS = (
    "cf_split_sum_model", "cf_split_sum_schlick", "cf_split_sum_lazanyi", "cf_average_fresnel",
)
"""The split-sum functions a coated-conductor snippet carries (cf_ibl)."""

TEMPLATE_DIR = Path(__file__).with_name("templates")
PACK_MEDIA_TYPES = {
    "binary": ("application/octet-stream", "cfpk"),
    "json": ("application/json", "json"),
    "glsl": ("text/plain; charset=utf-8", "glsl"),
    "hlsl": ("text/plain; charset=utf-8", "hlsl"),
}
EXPORT_MEDIA_TYPES = dict(EXPORT_FORMATS)
_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)


@functools.cache
def _template(name: str) -> string.Template:
    return string.Template((TEMPLATE_DIR / name).read_text())


_MODEL_FILES = {"coated-conductor": "cf_coated_conductor", "rgb-conductor": "cf_rgb_conductor"}


@functools.cache
def _model_source(language: str, kinds: tuple[str, ...]) -> str:
    """
    The function of each model kind in ``kinds``: GLSL from
    ``preview_shaders/glsl`` with its includes inlined (each file once),
    HLSL from the templates; with the coated-conductor kind, the split-sum
    functions too (``cf_ibl.glsl``; its HLSL twin ``templates/cf_ibl.hlsl``).
    """
    if language == "hlsl":
        files = [f"{_MODEL_FILES[k]}.hlsl" for k in kinds] + [f"{f}.hlsl" for f in _split_sum(kinds)]
        return "\n\n".join((TEMPLATE_DIR / f).read_text().strip() for f in files)
    seen: set[str] = set()

    def expand(file_name: str) -> str:
        if file_name in seen:
            return ""
        seen.add(file_name)
        return _INCLUDE.sub(lambda m: expand(m.group(1)), (GLSL_DIR / file_name).read_text())

    files = [f"{_MODEL_FILES[k]}.glsl" for k in kinds] + [f"{f}.glsl" for f in _split_sum(kinds)]
    source = "\n".join(expand(f).strip() for f in files)
    return _only_reachable(source, kinds).strip()


_FUNCTION_START = re.compile(r"^[A-Za-z_]\w*(?:\s+[A-Za-z_]\w*)*\s+([A-Za-z_]\w*)\s*\(")


def _only_reachable(source: str, kinds: tuple[str, ...]) -> str:
    """
    ``source`` without the top-level functions that the model functions of
    ``kinds`` (``cf_coated_conductor``, ``cf_rgb_conductor``) never call
    (with the comment just above each): the snippet ships only what its
    materials use, so no unused helper can need a newer GLSL version or an
    extension (``cf_unpack_coefficients`` needs ``unpackHalf2x16``, GLSL
    4.20 or ES 3.00).
    """
    lines = source.splitlines()
    items: list[tuple[str | None, list[str]]] = []  # (function name or None, lines)
    i = 0
    while i < len(lines):
        match = _FUNCTION_START.match(lines[i])
        if match and not lines[i].rstrip().endswith(";") and not lines[i].startswith("#"):
            comment: list[str] = []
            while items and items[-1][0] is None and items[-1][1] and items[-1][1][-1].startswith("//"):
                comment.insert(0, items[-1][1].pop())
            body, depth, opened = [], 0, False
            while i < len(lines):
                body.append(lines[i])
                depth += lines[i].count("{") - lines[i].count("}")
                opened = opened or "{" in lines[i]
                i += 1
                if opened and depth == 0:
                    break
            items.append((match.group(1), comment + body))
            continue
        if items and items[-1][0] is None:
            items[-1][1].append(lines[i])
        else:
            items.append((None, [lines[i]]))
        i += 1
    functions = {name: "\n".join(text) for name, text in items if name}
    keep, todo = set(), [_MODEL_FILES[k] for k in kinds]
    if _split_sum(kinds):
        todo += list(SPLIT_SUM_FUNCTIONS)
    while todo:
        name = todo.pop()
        if name in keep or name not in functions:
            continue
        keep.add(name)
        todo.extend(set(re.findall(r"\b([A-Za-z_]\w*)\s*\(", functions[name])) - keep)
    out = [line for name, text in items if name is None or name in keep for line in text]
    return re.sub(r"\n{3,}", "\n\n", "\n".join(out))


def _split_sum(kinds: tuple[str, ...]) -> list[str]:
    """The split-sum lookup (cf_ibl: cf_split_sum_model and the baselines,
    reading the LUT of GET /api/v1/ibl-lut) goes with the coated-conductor kind."""
    return ["cf_ibl"] if "coated-conductor" in kinds else []


@cached_once
def ibl_lut_file() -> bytes:
    """The default split-sum LUT as its file (:func:`fitting.shading.lut.encode_lut`),
    from the on-disk cache, once per process."""
    from fitting.shading.lut import default_lut, encode_lut

    return encode_lut(default_lut())


def glsl_identifier(name: str) -> str:
    """
    ``name`` as an identifier: letters, digits and single underscores (a
    double underscore is reserved in GLSL), never starting with a digit.
    """
    ident = re.sub(r"_+", "_", re.sub(r"[^A-Za-z0-9]", "_", name)).strip("_")
    if not ident or ident[0].isdigit():
        ident = "m_" + ident
    return ident.rstrip("_") or "m"


def _comment(text: str, limit: int = 160) -> str:
    """Text safe inside a // comment: one line of printable ASCII, no line splice."""
    flat = " ".join("".join(ch if 32 <= ord(ch) < 127 else " " for ch in text).split())
    flat = flat[:limit] + ("..." if len(flat) > limit else "")
    return flat.rstrip("\\ ") or "-"


def _literal(value: float) -> str:
    """A float16 value as a float literal that reads back exactly."""
    text = repr(float(value))
    return text if ("." in text or "e" in text) else text + ".0"


def _quality(record: FitRecord) -> str:
    model = record.metrics.get("model_float16")
    if not model:
        return "not measured"
    text = f"mean {model['delta_E_mean']:.3f}, max {model['delta_E_max']:.3f}"
    baseline = record.metrics.get("lazanyi_adjusted")
    if baseline:
        text += f" (adjusted Lazanyi: mean {baseline['delta_E_mean']:.3f})"
    return text


def _material_block(language: str, record: FitRecord, packed: PackedMaterial, ident: str) -> str:
    if packed.model == "rgb-conductor":
        n, k = (", ".join(_literal(v) for v in row) for row in packed.coefficients.astype(np.float64))
        return _template(f"material_rgb.{language}").substitute(
            name=_comment(record.name, 80), source=_comment(record.source), fit_id=record.id,
            quality=_quality(record), prefix=f"cf_{ident}", ident=ident, n=n, k=k,
        )
    C = np.zeros((3, 3, 3))
    C[:, :, : packed.degree + 1] = packed.coefficients.astype(np.float64)
    values = {
        p: ", ".join(_literal(v) for v in C[i].ravel()) for i, p in enumerate(("F0", "a", "alpha"))
    }
    lo, hi = packed.eta_i_range
    return _template(f"material.{language}").substitute(
        name=_comment(record.name, 80), source=_comment(record.source), fit_id=record.id,
        quality=_quality(record), prefix=f"cf_{ident}", ident=ident,
        eta_lo=_literal(lo), eta_hi=_literal(hi), **values,
    )


def _symbols(language: str, ident: str, packed: PackedMaterial) -> set[str]:
    """Every identifier the material block of ``ident`` (of ``packed``'s kind) defines."""
    block = "material_rgb" if packed.model == "rgb-conductor" else "material"
    text = (TEMPLATE_DIR / f"{block}.{language}").read_text()
    suffixes = set(re.findall(r"\$\{prefix\}(\w+)", text))
    return {f"cf_{ident}{s}" for s in suffixes} | {f"cf_material_{ident}"}


def _snippet(language: str, records: list[FitRecord], pack_name: str) -> str:
    materials = [(record, material_from_json(record.material)) for record in records]
    model = _model_source(language, tuple(k for k in _MODEL_FILES if any(p.model == k for _, p in materials)))
    # Symbols are unique within the pack: a material whose symbols would meet
    # another's (``material x`` and ``x F0`` both define cf_material_x_F0) or
    # the model's gets the next free suffix.
    used = set(re.findall(r"\b[A-Za-z_]\w*", model))
    blocks = []
    for record, packed in materials:
        ident = base = glsl_identifier(record.name)
        suffix = 2
        while _symbols(language, ident, packed) & used:
            ident, suffix = f"{base}_{suffix}", suffix + 1
        used |= _symbols(language, ident, packed)
        blocks.append(_material_block(language, record, packed, ident))
    return _template(f"pack.{language}").substitute(
        pack_name=_comment(pack_name, 80), count=len(records), fit_format=FIT_FORMAT_VERSION,
        model=model, materials="".join(blocks),
    )


def render_pack(records: list[FitRecord], format: str, pack_name: str) -> bytes:
    """
    The download of ``records`` in ``format`` (one of :data:`PACK_MEDIA_TYPES`).

    Raises
    ------
    ValueError
        For an unknown format or an empty list.
    """
    if format not in PACK_MEDIA_TYPES:
        raise ValueError(f"`format` must be one of {', '.join(PACK_MEDIA_TYPES)}, got {format!r}")
    if not records:
        raise ValueError("`fit_ids` must name at least one fit")
    if format == "binary":
        return encode_pack([material_from_json(r.material) for r in records])
    if format == "json":
        materials = []
        for record in records:
            view = material_from_json(record.material)
            materials.append(PackedMaterial(
                view.name, view.coefficients, view.eta_i_range, view.source, model=view.model,
                metrics={"fit_id": record.id, **{
                    key: record.metrics[key] for key in ("grid", "model_float16", "lazanyi_adjusted")
                    if key in record.metrics
                }},
            ))
        return pack_to_json(materials).encode("utf-8")
    return _snippet(format, records, pack_name).encode("utf-8")


def render_export(record: FitRecord, format: str, eta_i: float, roughness=0.2, coat_roughness=0.03) -> bytes:
    """
    The export of one stored fit in ``format`` (one of
    :data:`EXPORT_MEDIA_TYPES`) for the coating index ``eta_i`` and roughnesses.

    A fit of measured n, k is exported from them (the spectral reference
    under the coat); a fit made from edited curves from its own float16
    model curve, which it defines only on its eta_i domain. The fit's
    float16 model travels too (glTF: ``EXT_materials_coated_conductor``).

    Raises
    ------
    ValueError
        For an unknown format, eta_i outside [1, 3], or, for a curve fit,
        eta_i outside the fit's domain.
    """
    packed = material_from_json(record.material)
    if record.kind != "curves":
        nk = measured_nk(record)
        if nk is not None:
            return export_material(nk, format, eta_i, roughness, coat_roughness, model=packed)
    lo, hi = packed.eta_i_range
    if not lo <= eta_i <= hi:
        raise ValueError(
            f"`eta_i` must lie in the fit's domain [{lo:g}, {hi:g}] for an export of a fit "
            f"made from curves, got {eta_i:g}"
        )
    model = {
        "name": record.name, "source": record.source,
        "origin": f"float16 model curve of fit {record.id} (edited curves) under the coat",
        "reflectance": lambda mu, eta: model_ACEScg(
            packed.model, mu, eta, packed.coefficients, packed.eta_i_range),
    }
    return export_material(model, format, eta_i, roughness, coat_roughness, model=packed)


def render_export_pack(records: list[FitRecord], format: str, eta_i: float) -> bytes:
    """
    The exports of several fits for one ``eta_i``: a zip archive with one
    ``<name>-eta<eta_i>.<suffix>`` per fit, in order, byte-for-byte
    deterministic (fixed time stamps), so the same request gives the same
    archive. Entry names are unique (:func:`unique_names`), so that no
    material overwrites another when the archive is unpacked.
    """
    buffer = io.BytesIO()
    names = unique_names([download_name(f"{record.name}-eta{eta_i:g}", format) for record in records])
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for record, name in zip(records, names):
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, render_export(record, format, eta_i))
    return buffer.getvalue()


def unique_names(names: list[str]) -> list[str]:
    """``names``, each that repeats an earlier one ignoring case (``gold alloy`` and ``gold_alloy``
    both make ``gold_alloy``; a case-insensitive disk unpacks ``Gold`` over ``gold``) with ``-2``, ... added."""
    seen: set[str] = set()
    out = []
    for name in names:
        stem, dot, suffix = name.rpartition(".")
        candidate, k = name, 1
        while candidate.lower() in seen:
            k += 1
            candidate = f"{stem}-{k}{dot}{suffix}"
        seen.add(candidate.lower())
        out.append(candidate)
    return out


def download_name(stem: str, format: str) -> str:
    """``<stem>.<suffix>`` with only [A-Za-z0-9._-] in the stem (a safe header value)."""
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", stem).strip("._") or "material"
    suffix = {**PACK_MEDIA_TYPES, **EXPORT_MEDIA_TYPES}[format][1]
    return f"{safe[:80]}.{suffix}"


def pack_response(records: list[FitRecord], format: str, stem: str):
    """A download with its media type and Content-Disposition file name."""
    from fastapi import Response

    body = render_pack(records, format, stem)
    media_type, _ = PACK_MEDIA_TYPES[format]
    return Response(
        body, media_type=media_type,
        headers={"Content-Disposition": f'attachment; filename="{download_name(stem, format)}"'},
    )


def export_response(record: FitRecord, format: str, eta_i: float, stem: str, roughness=0.2, coat_roughness=0.03):
    """An export of one fit (:func:`render_export`) as a download named for ``eta_i`` and the roughnesses."""
    from fastapi import Response

    body = render_export(record, format, eta_i, roughness, coat_roughness)
    stem = f"{stem}-eta{eta_i:g}-rough{roughness:g}-coat{coat_roughness:g}"
    return Response(
        body, media_type=EXPORT_MEDIA_TYPES[format][0],
        headers={"Content-Disposition": f'attachment; filename="{download_name(stem, format)}"'},
    )


PACK_CONTENT = {
    "application/octet-stream": {"schema": {"type": "string", "format": "binary"}},
    "application/json": {"schema": {"type": "object"}},
    "text/plain": {"schema": {"type": "string"}},
    "application/xml": {"schema": {"type": "string"}},
    "text/x-python": {"schema": {"type": "string"}},
    "model/gltf+json": {"schema": {"type": "object"}},
    "application/zip": {"schema": {"type": "string", "format": "binary"}},
}
"""The OpenAPI content of a download."""
