"""
The editor's preview shader (glsl/shader_ball.frag, run in the browser as
GLSL ES 3.00) compiles and links as desktop GLSL 4.30 too, in a real
moderngl EGL context: the files are shared, not copied, so both compilers
must take them.
"""

from __future__ import annotations

import pytest

from preview_shaders.gl import load_shader_source

pytestmark = pytest.mark.gl


def test_shader_ball_compiles_as_desktop_glsl():
    import moderngl

    ctx = moderngl.create_context(standalone=True, backend="egl", require=430)
    try:
        program = ctx.program(
            vertex_shader=load_shader_source("fullscreen.vert"),
            fragment_shader=load_shader_source("shader_ball.frag"),
        )
        names = set(program)
        assert {"cf_words", "u_reference", "u_eye", "u_panel_kind", "u_output"} <= names
        program.release()
        # The rgb-conductor variants (static/kinds.js), mirror and split sum.
        # The mirror reads the packed words, the split sum its albedo table.
        for defines, used in (({"CF_RGB_CONDUCTOR": 1}, "cf_words"),
                              ({"CF_RGB_CONDUCTOR": 1, "CF_SPLIT_SUM": 1}, "u_albedo")):
            program = ctx.program(
                vertex_shader=load_shader_source("fullscreen.vert"),
                fragment_shader=load_shader_source("shader_ball.frag", defines),
            )
            assert used in set(program), defines
            program.release()
    finally:
        ctx.release()
