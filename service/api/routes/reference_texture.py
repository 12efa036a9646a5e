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

from fastapi import APIRouter, HTTPException, Response, status
from fastapi.concurrency import run_in_threadpool

from fitting.fits.curves_base import curve_base_from_nk
from fitting.models.baselines import baseline_inputs
from fitting.models.pack import material_from_json

from ...fitting_jobs import measured_nk
from ...models import API_PREFIX, ErrorBody
from ..deps import ERROR_RESPONSES, StoreDep
from .fits import FitIdPath, stored_fit

router = APIRouter(prefix=API_PREFIX, tags=["preview"])

__all__ = ["router", "reference_texture"]


def reference_texture(record) -> tuple[bytes, dict[str, str]]:
    """The texture bytes and headers of a stored fit (ValueError without n, k)."""
    nk = measured_nk(record)
    if nk is None:
        raise ValueError(f"fit {record.id} was made from curves alone: it has no n, k to take a reference from")
    packed = material_from_json(record.material)
    base = curve_base_from_nk(nk, packed.eta_i_range)
    inputs = baseline_inputs(nk)
    body = base.RGB.astype("<f4").tobytes()
    triple = lambda v: ",".join(f"{float(x):.9g}" for x in v)  # noqa: E731
    lo, hi = base.eta_i_range
    headers = {
        "X-Texture-Width": str(base.cos_theta.size),
        "X-Texture-Height": str(base.eta_i.size),
        "X-Eta-I-Range": f"{lo:.9g},{hi:.9g}",
        "X-F0-Air": triple(inputs["F0_air"]),
        "X-F82-Air": triple(inputs["F82_air"]),
        "Cache-Control": "max-age=86400, immutable",
    }
    return body, headers


@router.get(
    "/fits/{fit_id}/reference-texture",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {"content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}},
                             "description": "float32 RGB [eta_i row][cos theta column][channel]"},
        status.HTTP_404_NOT_FOUND: {"model": ErrorBody},
        **ERROR_RESPONSES,
    },
)
async def get_reference_texture(fit_id: FitIdPath, store: StoreDep) -> Response:
    """The fit's spectral reference over (cos theta, eta_i) as float32 RGB (see the headers)."""
    record = await run_in_threadpool(stored_fit, store, fit_id)
    try:
        body, headers = await run_in_threadpool(reference_texture, record)
    except ValueError as error:
        raise HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, str(error)) from None
    return Response(body, media_type="application/octet-stream", headers=headers)
