"""
The editor's preview shader (glsl/shader_ball.frag, run in the browser as
GLSL ES 3.00) compiles and links as desktop GLSL 4.30 too, in a real
moderngl EGL context, for every registered model kind: the files are
shared, not copied, and the kind's code is the include generated from the
registry (``preview_model_source(kind, inline=True)``, what
``GET /api/v1/domain`` serves the browser), so both compilers must take them.
"""

from __future__ import annotations

import pytest

from fitting.models.kinds import MODEL_KINDS
from preview_shaders.gl import load_shader_source
from preview_shaders.kinds import PREVIEW_MODEL_FILE, preview_model_source

pytestmark = pytest.mark.gl


def test_shader_ball_compiles_as_desktop_glsl_for_every_kind():
    import moderngl

    ctx = moderngl.create_context(standalone=True, backend="egl", require=430)
    try:
        vertex = load_shader_source("fullscreen.vert")
        for kind in MODEL_KINDS.values():
            sources = {PREVIEW_MODEL_FILE: preview_model_source(kind, inline=True)}
            # The mirror reads the packed words, the split sum its albedo table;
            # a kind without the split-sum lookup has its table row by quadrature.
            passes = [
                ("shader_ball.frag", {}, {"cf_words", "u_reference", "u_eye", "u_panel_kind", "u_output"}),
                ("shader_ball.frag", {"CF_SPLIT_SUM": 1}, {"u_albedo", "u_prefiltered"}),
            ]
            if not kind.split_sum:
                passes.append(("model_albedo_table.frag", {}, {"cf_words", "u_roughness", "u_samples"}))
            for name, defines, used in passes:
                program = ctx.program(vertex_shader=vertex, fragment_shader=load_shader_source(name, defines, sources))
                assert used <= set(program), (kind.name, name, defines)
                program.release()
    finally:
        ctx.release()
