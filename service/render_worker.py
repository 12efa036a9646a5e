"""
Render workers
==============

What runs in each process of the render pool (:class:`service.previews.PreviewRunner`):

-   :func:`render_worker_start`: a render process's initializer: a lower
    CPU priority (:data:`RENDER_NICENESS`), the fitting workers' start-up
    (:func:`service.worker.worker_start`: the shared ring of cancelled job
    serials, the warm-up, one BLAS thread), then the process's one preview
    renderer, whose GL context is made on its own render thread and used
    only there (:class:`preview_shaders.gl.RenderThread`).
-   :func:`renderer`: that renderer, or :class:`RendererUnavailable` when
    no GL context could be made.

The jobs themselves run under :func:`service.worker.run_part` (the CPU-time
limit and the server's cancellation, checked every 0.1 s).
"""

from __future__ import annotations

import os

from .worker import worker_start

__all__ = ["RENDER_NICENESS", "RendererUnavailable", "render_worker_start", "renderer"]

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
