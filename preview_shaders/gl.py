"""
Headless GL
===========

The one place where the GL context is made, and the dedicated thread that
owns it. A GL context works only on the thread that created it (elsewhere it
silently reads zeros), so every GL call of the package runs on a
:class:`RenderThread`.

-   :func:`load_shader_source`: a ``glsl/`` file with its ``#include``
    lines resolved and host ``#define`` lines inserted.
-   :class:`RenderThread`: owns a moderngl context (EGL, headless: Mesa's
    llvmpipe without a GPU) and runs callables on it, one at a time.
-   :class:`GLState`: what a callable gets on the render thread: the context
    and cached programs.
-   :func:`check_gl_error`: raises if the GL error state is not clean.
-   :func:`read_float_target`: an RGBA32F colour attachment as a numpy array.
-   :func:`time_renders`: timed full-screen renders, interleaved by round.
"""

from __future__ import annotations

import ctypes.util
import functools
import queue
import re
import threading
import time
from concurrent.futures import Future
from pathlib import Path
from typing import Any, Callable

import moderngl
import numpy as np

__all__ = [
    "GLSL_DIR",
    "GL_VERSION",
    "load_shader_source",
    "check_gl_error",
    "read_float_target",
    "time_renders",
    "GLState",
    "RenderThread",
]

GLSL_DIR = Path(__file__).with_name("glsl")
GL_VERSION = 430
"""GLSL 4.30 core: ``unpackHalf2x16`` and timer queries are core there."""

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)


def load_shader_source(name: str, defines: dict[str, int] | None = None, sources: dict[str, str] | None = None) -> str:
    """
    Source of ``glsl/<name>`` with ``#include "file"`` lines replaced by the
    file (recursively; each file is included once, its include guard covers
    repeats) and ``#define NAME value`` lines after the ``#version`` line.
    ``sources`` gives the text of generated include files by name (the
    preview's ``cf_preview_model.glsl``, :mod:`preview_shaders.kinds`); an
    absolute file name is read as it is.
    """
    seen: set[str] = set()
    sources = sources or {}

    def expand(file_name: str) -> str:
        if file_name in seen:
            return ""
        path = GLSL_DIR / file_name
        if file_name not in sources and not path.is_file():
            raise ValueError(f"`{file_name}` is not a shader in {GLSL_DIR}")
        seen.add(file_name)
        text = sources[file_name] if file_name in sources else path.read_text()
        return _INCLUDE.sub(lambda m: expand(m.group(1)), text)

    source = expand(name)
    head, _, body = source.partition("\n")
    if not head.startswith("#version"):
        raise ValueError(f"`{name}` must start with a #version line")
    lines = [f"#define {key} {int(value)}" for key, value in (defines or {}).items()]
    return "\n".join([head, *lines, body])


def read_float_target(fbo: moderngl.Framebuffer, index: int, width: int, height: int) -> np.ndarray:
    """
    Colour attachment ``index`` of an RGBA32F framebuffer as a (height, width,
    4) float32 array, rows bottom-up as GL stores them (a read-only view).
    """
    data = np.frombuffer(fbo.read(components=4, dtype="f4", attachment=index), np.float32)
    return data.reshape(height, width, 4)


def time_renders(ctx: moderngl.Context, vaos: dict[str, moderngl.VertexArray], rounds: int) -> dict[str, np.ndarray]:
    """
    Time a full-screen triangle of each of ``vaos`` into the bound
    framebuffer, interleaved round by round so drifting machine load hits
    every one alike, one warm-up render before each timed one. Per name, a
    (rounds, 3) array: GL timer query (ns), wall time (s) and process CPU
    time (s) of each timed render. Raises if the GL error state is not clean.
    """
    query = ctx.query(time=True)
    samples: dict[str, list] = {name: [] for name in vaos}
    for _ in range(rounds):
        for name, vao in vaos.items():
            for timed in (False, True):  # one warm-up render before each timed one
                ctx.finish()
                wall, cpu = time.perf_counter(), time.process_time()
                with query:
                    vao.render(mode=ctx.TRIANGLES, vertices=3)
                    # llvmpipe's query covers only completed work: finish inside.
                    ctx.finish()
                wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
                if timed:
                    samples[name].append((query.elapsed, wall, cpu))
    check_gl_error(ctx)
    return {name: np.array(s, dtype=np.float64) for name, s in samples.items()}


def check_gl_error(ctx: moderngl.Context) -> None:
    """Raise ``RuntimeError`` if the context's GL error state is not clean."""
    error = ctx.error
    if error != "GL_NO_ERROR":
        raise RuntimeError(f"GL error: {error}")


class GLState:
    """The render thread's context with its compiled programs, cached."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self._programs: dict[tuple, tuple[moderngl.Program, moderngl.VertexArray]] = {}
        # moderngl rebinds the previously bound framebuffer after creating a
        # new one; if that one was released, GL reports INVALID_OPERATION. A
        # framebuffer that is never released is bound before every release.
        self._idle = ctx.simple_framebuffer((1, 1))

    def float_targets(self, size: tuple[int, int], count: int):
        """A framebuffer with ``count`` RGBA32F colour attachments of ``size``."""
        targets = [self.ctx.texture(size, 4, dtype="f4") for _ in range(count)]
        return self.ctx.framebuffer(color_attachments=targets), targets

    def release_targets(self, fbo: moderngl.Framebuffer, targets) -> None:
        """Release what :meth:`float_targets` made."""
        self._idle.use()
        fbo.release()
        for target in targets:
            target.release()

    def program(
        self,
        fragment: str,
        defines: dict[str, int] | None = None,
        sources: dict[str, str] | None = None,
    ) -> tuple[moderngl.Program, moderngl.VertexArray]:
        """A full-screen program (``fullscreen.vert`` + ``fragment``, with the generated
        include ``sources`` of :func:`load_shader_source`) and its VAO."""
        key = (fragment, tuple(sorted((defines or {}).items())), tuple(sorted((sources or {}).items())))
        if key not in self._programs:
            program = self.ctx.program(
                vertex_shader=load_shader_source("fullscreen.vert"),
                fragment_shader=load_shader_source(fragment, defines, sources),
            )
            vao = self.ctx.vertex_array(program, [])
            self._programs[key] = (program, vao)
        return self._programs[key]


@functools.cache
def _gl_libraries() -> dict[str, str]:
    """
    libGL and libEGL for glcontext's EGL backend, looked up once a process:
    left to it, it looks both up at every context with
    ``ctypes.util.find_library``, which starts ``ldconfig -p`` (a fork of
    this process) each time. One not found is left to glcontext, as before.
    """
    found = {"libgl": ctypes.util.find_library("GL"), "libegl": ctypes.util.find_library("EGL")}
    return {key: name for key, name in found.items() if name}


def _create_context() -> moderngl.Context:
    """The one place a GL context is created (headless, EGL)."""
    return moderngl.create_context(standalone=True, backend="egl", require=GL_VERSION, **_gl_libraries())


class RenderThread:
    """
    A thread that owns one GL context and runs submitted callables on it.

    ``call(fn, *args)`` runs ``fn(state, *args)`` on the render thread with a
    :class:`GLState` and returns its result (or raises its exception); it is
    thread-safe, and calls run one at a time in submission order.

    Raises
    ------
    RuntimeError
        From the constructor, if no GL context can be created.
    """

    def __init__(self, name: str = "preview-render") -> None:
        self._jobs: queue.Queue = queue.Queue()
        self._ready: Future = Future()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()
        info = self._ready.result()
        self.renderer: str = info["GL_RENDERER"]
        self.version: str = info["GL_VERSION"]

    def _run(self) -> None:
        try:
            ctx = _create_context()
        except Exception as error:  # reported to the constructor's caller
            self._ready.set_exception(RuntimeError(f"no GL context: {error}"))
            return
        state = GLState(ctx)
        self._ready.set_result(dict(ctx.info))
        while True:
            job = self._jobs.get()
            if job is None:
                break
            fn, args, kwargs, future = job
            if not future.set_running_or_notify_cancel():
                continue
            try:
                future.set_result(fn(state, *args, **kwargs))
            except BaseException as error:
                future.set_exception(error)
        ctx.release()

    def call(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """Run ``fn(state, *args, **kwargs)`` on the render thread; return its result."""
        if not self._thread.is_alive():
            raise RuntimeError("the render thread is closed")
        future: Future = Future()
        self._jobs.put((fn, args, kwargs, future))
        return future.result()

    def close(self) -> None:
        """Stop the thread after the submitted work; release the context."""
        if self._thread.is_alive():
            self._jobs.put(None)
            self._thread.join()

    def __enter__(self) -> "RenderThread":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
