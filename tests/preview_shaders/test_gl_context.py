"""
preview_shaders.gl's contexts: libGL and libEGL are looked up once a
process (glcontext alone looks them up at every context, each time with
``ldconfig -p``, a fork of the process), and a context made with them is
the driver's.
"""

from __future__ import annotations

import ctypes.util

import pytest

from preview_shaders import gl
from preview_shaders.gl import RenderThread

pytestmark = pytest.mark.gl


def test_the_libraries_are_looked_up_once_a_process(monkeypatch):
    looked_up = []

    def find_library(name):
        looked_up.append(name)
        return original(name)

    original = ctypes.util.find_library
    monkeypatch.setattr(ctypes.util, "find_library", find_library)
    gl._gl_libraries.cache_clear()
    try:
        for _ in range(2):
            with RenderThread("gl-context-test") as thread:
                assert thread.renderer and thread.call(lambda state: state.ctx.info["GL_RENDERER"]) == thread.renderer
        assert sorted(looked_up) == ["EGL", "GL"]  # two contexts, one look-up of each
        assert gl._gl_libraries() == {"libgl": original("GL"), "libegl": original("EGL")}
    finally:
        gl._gl_libraries.cache_clear()
