"""
Reference texture
=================

``GET /api/v1/fits/{fit_id}/reference-texture``: the spectral reference of
a fit's measured n, k as a float texture over (cos theta, eta_i), for the
editor's real-time preview, which uses it as the Fresnel term of the
reference third of its split view.

The body is little-endian float32 RGB (linear ACEScg), row-major
``[eta_i row][cos theta column][channel]``:

-   ``X-Texture-Width`` columns: cos theta evenly over [0, 1] (257);
-   ``X-Texture-Height`` rows: eta_i evenly over ``X-Eta-I-Range`` (the fit's
    domain; 0.05 apart, 31 rows over [1, 2.5]; one row for a single index);
-   ``X-F0-Air`` and ``X-F82-Air``: the metal's F0 and F82 in air (linear
    ACEScg, ``r,g,b``), the inputs of adjusted Lazanyi.

It is the grid the curve fits blend their edits into
(:func:`fitting.fits.curves_base.curve_base_from_nk`, 5 nm spectral step), so a pixel
of the preview and a sample of an edited target agree; between samples the
shader interpolates bilinearly (``cf_reference_texture.glsl``). The texture
depends only on the fit, whose id is content-addressed: it is cacheable.
"""

from __future__ import annotations

from fastapi import APIRouter, Response, status
from fastapi.concurrency import run_in_threadpool

from ...jobs.common import stored_fit
from ...jobs.textures import reference_texture
from ...schemas import API_PREFIX
from ..deps import ERROR_RESPONSES, NOT_FOUND, FitIdPath, StoreDep

router = APIRouter(prefix=API_PREFIX, tags=["preview"])

__all__ = ["router"]


@router.get(
    "/fits/{fit_id}/reference-texture",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {
            "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}},
            "description": "float32 RGB [eta_i row][cos theta column][channel]",
        },
        **NOT_FOUND,
        **ERROR_RESPONSES,
    },
)
async def get_reference_texture(fit_id: FitIdPath, store: StoreDep) -> Response:
    """The fit's spectral reference over (cos theta, eta_i) as float32 RGB (see the headers)."""
    record = await run_in_threadpool(stored_fit, store, fit_id)
    body, headers = await run_in_threadpool(reference_texture, record)  # ValueError: 422
    return Response(body, media_type="application/octet-stream", headers=headers)
