"""
Shader snippets
===============

The ``glsl`` and ``hlsl`` downloads of stored fits: a ready-to-paste snippet
with the project's function of each model kind in the pack (its
:class:`fitting.models.kinds.ModelKind` names the file: GLSL from
``preview_shaders/glsl/`` with its includes inlined, HLSL from
``fitting/exports/templates/``), and per material the float16 coefficients as
constants and a ``cf_material_<name>(NdotV, eta_i)`` function (the kind's
material template). With a kind that has the split-sum lookup
(``ModelKind.split_sum``: the coated-conductor), the snippet also carries
``cf_split_sum_model`` (and the baselines), which reads the LUT of ``GET
/api/v1/ibl-lut`` (``cf_ibl.glsl``, ``templates/cf_ibl.hlsl``).

Each material's header quotes its figures (:attr:`SnippetMaterial.quality`:
the service and the CLI give :func:`fitting.fits.metrics.headline` of the
fit's metrics), with what they were measured against in words, the same
numbers as the JSON download.

-   :class:`SnippetMaterial`: one material of a snippet.
-   :func:`snippet`: the text of a download.
-   :func:`model_source`: the functions of a set of kinds.
-   :func:`glsl_identifier`: a material name as a GLSL/HLSL identifier.
"""

from __future__ import annotations

import functools
import re
import string
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..models.kinds import MODEL_KINDS, model_kind
from ..models.pack import PackedMaterial

__all__ = [
    "GLSL_DIR",
    "TEMPLATE_DIR",
    "SPLIT_SUM_FUNCTIONS",
    "SnippetMaterial",
    "snippet",
    "model_source",
    "glsl_identifier",
]

TEMPLATE_DIR = Path(__file__).with_name("templates")
GLSL_DIR = Path(__file__).resolve().parents[2] / "preview_shaders" / "glsl"
"""The project's GLSL files (read as files: ``fitting`` never imports ``preview_shaders``)."""
SPLIT_SUM_FUNCTIONS = (
    "cf_split_sum_model",
    "cf_split_sum_schlick",
    "cf_split_sum_lazanyi",
    "cf_average_fresnel",
)
"""The split-sum functions a snippet with a split-sum kind carries (cf_ibl)."""

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)
_FUNCTION_START = re.compile(r"^[A-Za-z_]\w*(?:\s+[A-Za-z_]\w*)*\s+([A-Za-z_]\w*)\s*\(")


@functools.cache
def _template(path: Path) -> string.Template:
    return string.Template(path.read_text())


def _material_template(stem: str, language: str) -> Path:
    """The material block template of a kind (``TEMPLATE_DIR / stem``; an absolute stem is kept)."""
    return TEMPLATE_DIR / f"{stem}.{language}"


def _split_sum(kinds: tuple[str, ...]) -> list[str]:
    """The split-sum lookup (cf_ibl), with a kind that has it."""
    return ["cf_ibl"] if any(model_kind(k).split_sum for k in kinds) else []


@functools.cache
def model_source(language: str, kinds: tuple[str, ...]) -> str:
    """
    The function of each model kind in ``kinds``: GLSL from
    ``preview_shaders/glsl`` with its includes inlined (each file once),
    HLSL from the templates; with a split-sum kind, the split-sum functions
    too (``cf_ibl.glsl``; its HLSL twin ``templates/cf_ibl.hlsl``).
    """
    if language == "hlsl":
        files = [TEMPLATE_DIR / model_kind(k).hlsl_file for k in kinds]
        files += [TEMPLATE_DIR / f"{f}.hlsl" for f in _split_sum(kinds)]
        return "\n\n".join(f.read_text().strip() for f in files)
    seen: set[str] = set()

    def expand(file_name: str) -> str:
        if file_name in seen:
            return ""
        seen.add(file_name)
        return _INCLUDE.sub(lambda m: expand(m.group(1)), (GLSL_DIR / file_name).read_text())

    names = [model_kind(k).glsl_file for k in kinds] + [f"{f}.glsl" for f in _split_sum(kinds)]
    source = "\n".join(expand(name).strip() for name in names)
    return _only_reachable(source, kinds).strip()


def _only_reachable(source: str, kinds: tuple[str, ...]) -> str:
    """
    ``source`` without the top-level functions that the model functions of
    ``kinds`` (``ModelKind.glsl_function``) never call (with the comment just
    above each): the snippet ships only what its materials use, so no unused
    helper can need a newer GLSL version or an extension
    (``cf_unpack_coefficients`` needs ``unpackHalf2x16``, GLSL 4.20 or ES 3.00).
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
    keep, todo = set(), [model_kind(k).glsl_function for k in kinds]
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


@dataclass(frozen=True)
class SnippetMaterial:
    """
    One material of a snippet: its ``name`` and ``source`` (quoted in its
    header), the ``fit_id`` it came from, ``quality`` (its headline figures
    in words, one line) and its float16 model ``packed``.
    """

    name: str
    source: str
    fit_id: str
    quality: str
    packed: PackedMaterial


def _material_block(language: str, material: SnippetMaterial, ident: str) -> str:
    packed = material.packed
    kind = model_kind(packed.model)
    C = packed.coefficients.astype(np.float64)
    if kind.polynomial:
        # Every power up to the kind's highest (a lower degree padded with zero powers: the same model).
        padded = np.zeros(kind.shape(kind.max_degree))
        padded[..., : packed.degree + 1] = C
        C = padded
    values = {p: ", ".join(_literal(v) for v in C[i].ravel()) for i, p in enumerate(kind.parameters)}
    lo, hi = packed.eta_i_range
    return _template(_material_template(kind.material_template, language)).substitute(
        name=_comment(material.name, 80),
        source=_comment(material.source),
        fit_id=material.fit_id,
        model=kind.name,
        quality=_comment(material.quality, 400),
        prefix=f"cf_{ident}",
        ident=ident,
        eta_lo=_literal(lo),
        eta_hi=_literal(hi),
        **values,
    )


def _symbols(language: str, ident: str, packed: PackedMaterial) -> set[str]:
    """Every identifier the material block of ``ident`` (of ``packed``'s kind) defines."""
    text = _material_template(model_kind(packed.model).material_template, language).read_text()
    suffixes = set(re.findall(r"\$\{prefix\}(\w+)", text))
    return {f"cf_{ident}{s}" for s in suffixes} | {f"cf_material_{ident}"}


def snippet(language: str, materials: list[SnippetMaterial], pack_name: str, fit_format: str) -> str:
    """The ``glsl`` or ``hlsl`` snippet of ``materials`` (see the module docstring)."""
    used_kinds = {material.packed.model for material in materials}
    model = model_source(language, tuple(k for k in MODEL_KINDS if k in used_kinds))
    # Symbols are unique within the pack: a material whose symbols would meet
    # another's (``material x`` and ``x F0`` both define cf_material_x_F0) or
    # the model's gets the next free suffix.
    used = set(re.findall(r"\b[A-Za-z_]\w*", model))
    blocks = []
    for material in materials:
        ident = base = glsl_identifier(material.name)
        suffix = 2
        while _symbols(language, ident, material.packed) & used:
            ident, suffix = f"{base}_{suffix}", suffix + 1
        used |= _symbols(language, ident, material.packed)
        blocks.append(_material_block(language, material, ident))
    return _template(TEMPLATE_DIR / f"pack.{language}").substitute(
        pack_name=_comment(pack_name, 80),
        count=len(materials),
        fit_format=fit_format,
        model=model,
        materials="".join(blocks),
    )
