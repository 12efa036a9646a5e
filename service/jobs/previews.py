"""
Previews
========

-   :func:`render_preview`: the preview sphere of a stored fit as PNG bytes,
    drawn in the render pool (:class:`service.runtime.previews.PreviewRunner`): one
    job per distinct request in flight, never on the server's event loop.
-   :func:`preview_png`: what a render process runs for it
    (:meth:`preview_shaders.preview.PreviewRenderer.render_preview` on the
    process's own renderer, the PNG encoded there too).
-   :func:`preview_cost_s`: a preview's estimated CPU seconds, from which
    the render pool gives it its CPU budget and admits it
    (:class:`service.runtime.previews.PreviewRunner`).

What drives a preview's CPU (``benchmarks/render_cost.py``, recorded in
``benchmarks/results/render_cost.json``): its pixels, and whether it is
drawn through the split sum (rough or coated: about 2.5 times a smooth
view's seconds per pixel, and a fixed 0.2 s more with the spectral
reference). The comparison of a smooth view and the environment move it
less than the measurements vary (no environment is the dearest in every
view), so they are not in the estimate.
"""

from __future__ import annotations

import asyncio

from fitting.models.pack import PackedMaterial, material_from_json
from fitting.optics.nk import SpectralNK

from ..runtime import PreviewRunner, renderer
from ..store import FitRecord
from .common import measured_nk

__all__ = ["render_preview", "preview_png", "preview_cost_s", "PREVIEW_COST_S"]

PREVIEW_COST_S = {"smooth": (0.02, 0.55), "split_sum": (0.05, 1.35), "split_sum_reference": (0.25, 1.35)}
"""Each kind of view's CPU seconds, fixed and per megapixel, rounded up from a run of benchmarks/render_cost.py at a
load of 2 (no render above its estimate); on a loaded machine a render's clock runs longer (the recorded run, at a load
of 10-11: at most 1.36 times), well within its budget of 3 times (service.runtime.budget)."""


def preview_cost_s(size: int, compare: str, roughness: float, mode: str) -> float:
    """The estimated CPU seconds of a ``size`` px preview (see the module docstring)."""
    if roughness > 0.0 or mode != "immersed":
        view = "split_sum_reference" if compare == "reference" else "split_sum"
    else:
        view = "smooth"
    fixed_s, per_megapixel_s = PREVIEW_COST_S[view]
    return fixed_s + per_megapixel_s * size * size / 1e6


def preview_png(
    packed: PackedMaterial,
    nk: SpectralNK | None,
    eta_i: float,
    size: int,
    compare: str,
    environment: str,
    roughness: float,
    mode: str,
    coat_roughness: float,
) -> bytes:
    """Render process: the preview's 8-bit sRGB PNG (ValueError for a view the fit's kind cannot draw)."""
    return (
        renderer()
        .render_preview(
            packed,
            nk,
            eta_i=eta_i,
            size=size,
            compare=compare,
            environment=environment,
            differences=False,
            roughness=roughness,
            mode=mode,
            coat_roughness=coat_roughness,
        )
        .png
    )


def _inputs(record: FitRecord) -> tuple[PackedMaterial, SpectralNK | None]:
    return material_from_json(record.material), measured_nk(record)


async def render_preview(
    runner: PreviewRunner,
    record: FitRecord,
    *,
    eta_i: float,
    size: int,
    compare: str,
    environment: str,
    roughness: float,
    mode: str,
    coat_roughness: float,
) -> bytes:
    """
    The PNG of ``record``'s preview (the parameters of
    :func:`preview_png`), rendered in a render process.

    Raises
    ------
    ValueError
        A comparison of a fit made from curves alone (no n, k), or a view
        its model kind cannot draw.
    service.runtime.previews.PreviewsBusy, PreviewTimeout, RenderWorkerLost, RendererUnavailable
    service.runtime.budget.RenderTooCostly, RenderBudgetExceeded
        Its estimate passes the CPU-time limit of a job; it used its CPU budget.
    """
    packed, nk = await asyncio.to_thread(_inputs, record)
    if compare != "none" and nk is None:
        raise ValueError(f"`compare`={compare!r} needs measured n, k; fit {record.id} was made from curves")
    params = (eta_i, size, compare, environment, roughness, mode, coat_roughness)
    cost_s = preview_cost_s(size, compare, roughness, mode)
    return await runner.preview((record.id, *params), preview_png, packed, nk, *params, cost_s=cost_s)
