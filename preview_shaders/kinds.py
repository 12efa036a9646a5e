"""
How the preview draws each model kind
=====================================

The preview's programs (``glsl/preview.frag``) include
``cf_preview_model.glsl``, made here per model kind from its
:class:`fitting.models.kinds.ModelKind`: the kind's GLSL file and one
function ``cf_preview_model(NdotV, eta_i, eta_i_range, words)`` returning
its ``preview_call``. Every kind shares one uniform layout: ``cf_words``,
14 uint32 of its float16 coefficients (two per word, zero-padded), so a new
kind is drawn with no change here.

-   :data:`PREVIEW_MODEL_FILE`: the include's name.
-   :func:`preview_model_source`: its source for a kind (``inline=True``:
    the kind's own file pasted in when it lies outside ``glsl/``, the form
    ``GET /api/v1/domain`` serves the browser, whose loader fetches only
    ``glsl/``'s files).
-   :func:`preview_words`: a material's 14 uniform words.
-   :func:`padded_words`: the same for a kind with a power axis, every power there.
"""

from __future__ import annotations

import numpy as np

from pathlib import Path

from fitting.models.kinds import PREVIEW_WORDS, ModelKind, model_kind
from fitting.models.pack import PackedMaterial, halves_to_uint32

GLSL_DIR = Path(__file__).with_name("glsl")

__all__ = ["PREVIEW_MODEL_FILE", "preview_model_source", "preview_words", "padded_words"]

PREVIEW_MODEL_FILE = "cf_preview_model.glsl"


def preview_model_source(kind: ModelKind, inline: bool = False) -> str:
    """
    The include ``cf_preview_model.glsl`` of the preview for ``kind``; with
    ``inline``, a kind's file outside ``glsl/`` (an absolute path) is pasted
    in instead of included (its own ``#include`` lines name ``glsl/``'s files).
    """
    own = Path(kind.glsl_file)
    shared = not own.is_absolute() and (GLSL_DIR / own).is_file()
    code = f'#include "{kind.glsl_file}"' if shared or not inline else own.read_text(encoding="utf-8").rstrip("\n")
    return "\n".join(
        [
            "#ifndef CF_PREVIEW_MODEL_GLSL",
            "#define CF_PREVIEW_MODEL_GLSL",
            code,
            f"// The {kind.name} kind from its float16 coefficients, two per word (fitting.models.kinds).",
            f"vec3 cf_preview_model(float NdotV, float eta_i, vec2 eta_i_range, uint words[{PREVIEW_WORDS}])",
            "{",
            f"    return {kind.preview_call};",
            "}",
            "#endif",
            "",
        ]
    )


def _padded(packed: PackedMaterial) -> np.ndarray:
    """The float16 coefficients, a kind with a power axis padded with zero powers to its highest degree."""
    kind = model_kind(packed.model)
    C = np.asarray(packed.coefficients, dtype=np.float16)
    if not kind.polynomial:
        return C
    padded = np.zeros(kind.shape(kind.max_degree), dtype=np.float16)
    padded[..., : C.shape[-1]] = C
    return padded


def preview_words(packed: PackedMaterial) -> np.ndarray:
    """The :data:`~fitting.models.kinds.PREVIEW_WORDS` uint32 words of ``packed``'s coefficients, zero-padded."""
    words = np.zeros(PREVIEW_WORDS, dtype=np.uint32)
    packed_words = halves_to_uint32(_padded(packed))
    words[: packed_words.size] = packed_words
    return words


def padded_words(packed: PackedMaterial) -> np.ndarray:
    """The 14 uint32 words of a coated-conductor's coefficients, padded to degree 2."""
    return halves_to_uint32(_padded(packed))
