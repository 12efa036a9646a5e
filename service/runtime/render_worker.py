"""
Render workers
==============

What runs in each process of the render pool (:class:`service.runtime.previews.PreviewRunner`):

-   :func:`render_worker_start`: a render process's initializer: a lower
    CPU priority (:data:`RENDER_NICENESS`), the fitting workers' start-up
    (:func:`service.runtime.worker.worker_start`: the shared ring of cancelled job
    serials, the warm-up, one BLAS thread), then the process's one preview
    renderer, whose GL context is made on its own render thread and used
    only there (:class:`preview_shaders.gl.RenderThread`).
-   :func:`renderer`: that renderer, or :class:`RendererUnavailable` when
    no GL context could be made.
-   :func:`run_render_part`: a job, under :func:`service.runtime.worker.run_part`
    (the CPU-time limit and the server's cancellation, checked every 0.1 s),
    once the render thread has finished what a stopped job left on it.
"""

from __future__ import annotations

import os

from .worker import run_part, worker_start

__all__ = ["RENDER_NICENESS", "RendererUnavailable", "render_worker_start", "renderer", "run_render_part"]

RENDER_NICENESS = 10
"""Added to a render process's nice value before any of its threads start (the GL
thread and Mesa's llvmpipe threads inherit it): on a machine whose cores a
preview fills, the server's event loop is scheduled first."""

_renderer = None  # in a render process: its PreviewRenderer
_unavailable: str | None = None  # ... or why there is none


class RendererUnavailable(Exception):
    """No GL context can be made on this machine (503); the rest of the service works."""

    def __init__(self, reason: str) -> None:
        super().__init__(f"the preview renderer is unavailable: {reason}")
        self.reason = reason

    def __reduce__(self):  # raised in a render process, re-raised in the server
        return RendererUnavailable, (self.reason,)


def render_worker_start(cancelled) -> None:
    """
    A render process's initializer. A machine without a GL driver still
    starts the process (an initializer that raises would break the pool
    for good); its jobs answer :class:`RendererUnavailable`.
    """
    global _renderer, _unavailable
    os.nice(RENDER_NICENESS)
    worker_start(cancelled)
    try:
        from preview_shaders.preview import PreviewRenderer

        _renderer = PreviewRenderer()
    except Exception as error:
        _unavailable = str(error)


def renderer():
    """This render process's :class:`preview_shaders.preview.PreviewRenderer`."""
    if _renderer is None:
        raise RendererUnavailable(_unavailable or "the render process did not start")
    return _renderer


def _idle(state) -> None:
    """A no-op on the render thread: it runs once every call before it has."""


def run_render_part(serial: int, cpu_limit_s: float, function, *args):
    """
    ``function(*args)`` under :func:`service.runtime.worker.run_part`, after the
    render thread has finished what it was given before. A job stopped at
    its CPU-time limit or cancelled stops waiting for the render thread, but
    the GL call it was in runs to its end there (a GL call cannot be
    interrupted); without the wait that leftover work ran beside the next
    job, on that job's CPU-time clock (a 64 px preview after a stopped 2048
    px one was refused at a limit of 1 s, in a loaded test run).
    """
    if _renderer is not None:
        _renderer.thread.call(_idle)
    return run_part(serial, cpu_limit_s, function, *args)
