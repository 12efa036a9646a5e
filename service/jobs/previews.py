"""
Previews
========

-   :func:`render_preview`: the preview sphere of a stored fit as PNG bytes,
    drawn in the render pool (:class:`service.runtime.previews.PreviewRunner`): one
    job per distinct request in flight, never on the server's event loop.
-   :func:`preview_png`: what a render process runs for it
    (:meth:`preview_shaders.preview.PreviewRenderer.render_preview` on the
    process's own renderer, the PNG encoded there too).
"""

from __future__ import annotations

import asyncio

from fitting.models.pack import PackedMaterial, material_from_json
from fitting.optics.nk import SpectralNK

from ..runtime import PreviewRunner, renderer
from ..store import FitRecord
from .common import measured_nk

__all__ = ["render_preview", "preview_png"]


def preview_png(packed: PackedMaterial, nk: SpectralNK | None, eta_i: float, size: int, compare: str,
                environment: str, roughness: float, mode: str, coat_roughness: float) -> bytes:
    """Render process: the preview's 8-bit sRGB PNG (ValueError for a view the fit's kind cannot draw)."""
    return renderer().render_preview(
        packed, nk, eta_i=eta_i, size=size, compare=compare, environment=environment,
        differences=False, roughness=roughness, mode=mode, coat_roughness=coat_roughness,
    ).png


def _inputs(record: FitRecord) -> tuple[PackedMaterial, SpectralNK | None]:
    return material_from_json(record.material), measured_nk(record)


async def render_preview(runner: PreviewRunner, record: FitRecord, *, eta_i: float, size: int, compare: str,
                         environment: str, roughness: float, mode: str, coat_roughness: float) -> bytes:
    """
    The PNG of ``record``'s preview (the parameters of
    :func:`preview_png`), rendered in a render process.

    Raises
    ------
    ValueError
        A comparison of a fit made from curves alone (no n, k), or a view
        its model kind cannot draw.
    service.runtime.previews.PreviewsBusy, PreviewTimeout, RenderWorkerLost, RendererUnavailable
    """
    packed, nk = await asyncio.to_thread(_inputs, record)
    if compare != "none" and nk is None:
        raise ValueError(f"`compare`={compare!r} needs measured n, k; fit {record.id} was made from curves")
    params = (eta_i, size, compare, environment, roughness, mode, coat_roughness)
    return await runner.preview((record.id, *params), preview_png, packed, nk, *params)
