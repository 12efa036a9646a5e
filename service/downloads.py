"""
Pack downloads
==============

Stored fits as the files a renderer loads:

-   ``binary``: the documented binary pack (:func:`fitting.pack.encode_pack`).
-   ``json``: its JSON view (:func:`fitting.pack.pack_to_json`).
-   ``glsl``: a ready-to-paste snippet: the project's GLSL model
    (``preview_shaders/glsl/cf_coated_conductor.glsl`` and its include,
    inlined) and per material the float16 coefficients as constants and a
    ``cf_material_<name>(NdotV, eta_i)`` function.
-   ``hlsl``: the same for HLSL, with the HLSL model from
    ``service/templates/cf_coated_conductor.hlsl``.

The snippet text comes from the template files in ``service/templates/``.

-   :data:`PACK_MEDIA_TYPES`: media type and file suffix per format.
-   :func:`render_pack`: the bytes of a download.
-   :func:`download_name`: a safe file name for Content-Disposition.
-   :func:`glsl_identifier`: a material name as a GLSL/HLSL identifier.
"""

from __future__ import annotations

import functools
import re
import string
from pathlib import Path

import numpy as np

from fitting.models.pack import PackedMaterial, encode_pack, material_from_json, pack_to_json
from preview_shaders.gl import GLSL_DIR

from .fitting_jobs import FIT_FORMAT_VERSION
from .store import FitRecord

__all__ = ["PACK_MEDIA_TYPES", "TEMPLATE_DIR", "render_pack", "download_name", "glsl_identifier"]

TEMPLATE_DIR = Path(__file__).with_name("templates")
PACK_MEDIA_TYPES = {
    "binary": ("application/octet-stream", "cfpk"),
    "json": ("application/json", "json"),
    "glsl": ("text/plain; charset=utf-8", "glsl"),
    "hlsl": ("text/plain; charset=utf-8", "hlsl"),
}
_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)


@functools.cache
def _template(name: str) -> string.Template:
    return string.Template((TEMPLATE_DIR / name).read_text())


@functools.cache
def _glsl_model() -> str:
    """cf_coated_conductor.glsl with its includes inlined (each file once)."""
    seen: set[str] = set()

    def expand(file_name: str) -> str:
        if file_name in seen:
            return ""
        seen.add(file_name)
        return _INCLUDE.sub(lambda m: expand(m.group(1)), (GLSL_DIR / file_name).read_text())

    return expand("cf_coated_conductor.glsl").strip()


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


def _snippet(language: str, records: list[FitRecord], pack_name: str) -> str:
    used: set[str] = set()
    blocks = []
    for record in records:
        ident = base = glsl_identifier(record.name)
        suffix = 2
        while ident in used:
            ident, suffix = f"{base}_{suffix}", suffix + 1
        used.add(ident)
        blocks.append(_material_block(language, record, material_from_json(record.material), ident))
    model = _glsl_model() if language == "glsl" else (TEMPLATE_DIR / "cf_coated_conductor.hlsl").read_text().strip()
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
                view.name, view.coefficients, view.eta_i_range, view.source,
                metrics={"fit_id": record.id, **{
                    key: record.metrics[key] for key in ("grid", "model_float16", "lazanyi_adjusted")
                    if key in record.metrics
                }},
            ))
        return pack_to_json(materials).encode("utf-8")
    return _snippet(format, records, pack_name).encode("utf-8")


def download_name(stem: str, format: str) -> str:
    """``<stem>.<suffix>`` with only [A-Za-z0-9._-] in the stem (a safe header value)."""
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", stem).strip("._") or "material"
    return f"{safe[:80]}.{PACK_MEDIA_TYPES[format][1]}"
