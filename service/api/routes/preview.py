"""
Preview
=======

``GET /api/v1/preview.png?fit=ID&eta_i=1.5&size=512&compare=none``
(``&roughness=0.3&mode=coated&coat_roughness=0.1``): the
preview sphere of a stored fit (``preview_shaders.preview``), optionally
split with adjusted Lazanyi or the spectral reference (these need the
fit's n, k). Rendered and encoded in the render pool
(:class:`service.runtime.previews.PreviewRunner`, :func:`service.jobs.previews.render_preview`),
never in the server process: at most ``max_previews_in_flight`` previews
render at once (the spectral reference of a large preview is seconds of
CPU), past it a request is answered 503 with Retry-After rather than
queued; identical requests in flight share one render; a request waits at
most ``preview_timeout_s`` (504), and a preview no request waits for any
more (its client went away) is cancelled.
"""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Query, Request, Response, status
from fastapi.concurrency import run_in_threadpool

from preview_shaders.preview import ENVIRONMENTS

from ...jobs.common import stored_fit
from ...jobs.previews import render_preview
from ...schemas import API_PREFIX, ETA_I_LIMITS, FIT_ID_PATTERN, ErrorBody
from ..deps import ERROR_RESPONSES, PreviewsDep, SettingsDep, StoreDep

router = APIRouter(prefix=API_PREFIX, tags=["preview"])


@router.get(
    "/preview.png",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {"content": {"image/png": {"schema": {"type": "string", "format": "binary"}}}},
        status.HTTP_404_NOT_FOUND: {"model": ErrorBody},
        **ERROR_RESPONSES,
        status.HTTP_503_SERVICE_UNAVAILABLE: {
            "model": ErrorBody,
            "description": ("COATED_MAX_PREVIEWS_IN_FLIGHT previews rendering (Retry-After), or no GL on this machine"),
        },
        status.HTTP_504_GATEWAY_TIMEOUT: {
            "model": ErrorBody,
            "description": ("The preview ran past COATED_PREVIEW_TIMEOUT_S and was cancelled (Retry-After)"),
        },
    },
)
async def preview_png(
    store: StoreDep,
    settings: SettingsDep,
    previews: PreviewsDep,
    http: Request,
    fit: Annotated[str, Query(pattern=FIT_ID_PATTERN, description="A stored fit's id")],
    eta_i: Annotated[float, Query(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False)] = 1.5,
    size: Annotated[int, Query(ge=64, le=2048, description="Pixels per side")] = 512,
    compare: Annotated[Literal["none", "lazanyi", "reference"], Query()] = "none",
    environment: Annotated[
        Literal[ENVIRONMENTS],
        Query(  # type: ignore[valid-type]
            description="The light around the sphere (as the CLI's `render --environment`)"
        ),
    ] = "white_sky",
    roughness: Annotated[
        float, Query(ge=0.0, le=1.0, allow_inf_nan=False, description="GGX perceptual roughness of the metal")
    ] = 0.0,
    mode: Annotated[
        Literal["immersed", "coated"],
        Query(
            description="immersed: the camera in the medium of index eta_i; coated: a clear coat of "
            "index eta_i seen from air"
        ),
    ] = "immersed",
    coat_roughness: Annotated[
        float, Query(ge=0.0, le=1.0, allow_inf_nan=False, description="The coat's roughness (mode=coated)")
    ] = 0.0,
) -> Response:
    """The preview sphere as an 8-bit sRGB PNG: smooth (roughness 0, immersed),
    or rough / coated through the split sum with a prefiltered environment."""
    if size > settings.max_preview_size:
        raise ValueError(
            f"`size` must be at most {settings.max_preview_size} (COATED_MAX_PREVIEW_SIZE), got {size}",
        )
    # A fit never changes, nor does its preview: kept (service.derived), a repeat is a lookup.
    key = ("preview", fit, eta_i, size, compare, environment, roughness, mode, coat_roughness)
    png = http.app.state.derived.get(key)
    if png is None:
        record = await run_in_threadpool(stored_fit, store, fit)
        png = await http.app.state.derived.get_or_make(
            key,
            lambda: render_preview(
                previews,
                record,
                eta_i=eta_i,
                size=size,
                compare=compare,
                environment=environment,
                roughness=roughness,
                mode=mode,
                coat_roughness=coat_roughness,
            ),
        )
    return Response(png, media_type="image/png", headers={"Cache-Control": "max-age=3600"})
