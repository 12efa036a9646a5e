"""
Preview
=======

``GET /api/v1/preview.png?fit=ID&eta_i=1.5&size=512&compare=none``
(``&roughness=0.3&mode=coated&coat_roughness=0.1``): the
preview sphere of a stored fit (``preview_shaders.preview``), optionally
split with adjusted Lazanyi or the spectral reference (these need the
fit's n, k). One renderer per app (:func:`service.api.deps.get_preview_renderer`),
made on first use; it owns its GL thread, so concurrent requests are
serialised there. At most
``max_previews_in_flight`` previews are computed at once (the spectral
reference of a large preview is seconds of CPU); past it a request is
answered 503 with Retry-After rather than queued.
"""

from __future__ import annotations

import threading
from typing import Annotated, Literal

from fastapi import APIRouter, HTTPException, Query, Request, Response, status

from fitting.models.pack import material_from_json

from ...jobs.common import measured_nk, stored_fit
from ...schemas import API_PREFIX, ETA_I_LIMITS, FIT_ID_PATTERN, ErrorBody
from ..deps import ERROR_RESPONSES, SettingsDep, StoreDep, get_preview_renderer

router = APIRouter(prefix=API_PREFIX, tags=["preview"])
_lock = threading.Lock()


def _slots(request: Request, settings) -> threading.BoundedSemaphore:
    """The app's bound on previews in flight, made on first use."""
    state = request.app.state
    with _lock:
        if getattr(state, "preview_slots", None) is None:
            state.preview_slots = threading.BoundedSemaphore(settings.max_previews_in_flight)
        return state.preview_slots


@router.get(
    "/preview.png",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {"content": {"image/png": {"schema": {"type": "string", "format": "binary"}}}},
        status.HTTP_404_NOT_FOUND: {"model": ErrorBody},
        status.HTTP_503_SERVICE_UNAVAILABLE: {"model": ErrorBody},
        **ERROR_RESPONSES,
    },
)
def preview_png(
    request: Request, store: StoreDep, settings: SettingsDep,
    fit: Annotated[str, Query(pattern=FIT_ID_PATTERN, description="A stored fit's id")],
    eta_i: Annotated[float, Query(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False)] = 1.5,
    size: Annotated[int, Query(ge=64, le=2048, description="Pixels per side")] = 512,
    compare: Annotated[Literal["none", "lazanyi", "reference"], Query()] = "none",
    environment: Annotated[Literal["white_sky", "studio"], Query()] = "white_sky",
    roughness: Annotated[float, Query(ge=0.0, le=1.0, allow_inf_nan=False,
                                      description="GGX perceptual roughness of the metal")] = 0.0,
    mode: Annotated[Literal["immersed", "coated"], Query(
        description="immersed: the camera in the medium of index eta_i; coated: a clear coat of "
                    "index eta_i seen from air")] = "immersed",
    coat_roughness: Annotated[float, Query(ge=0.0, le=1.0, allow_inf_nan=False,
                                           description="The coat's roughness (mode=coated)")] = 0.0,
) -> Response:
    """The preview sphere as an 8-bit sRGB PNG: smooth (roughness 0, immersed),
    or rough / coated through the split sum with a prefiltered environment."""
    if size > settings.max_preview_size:
        raise ValueError(
            f"`size` must be at most {settings.max_preview_size} (COATED_MAX_PREVIEW_SIZE), got {size}",
        )
    record = stored_fit(store, fit)
    nk = measured_nk(record)
    if compare != "none" and nk is None:
        raise ValueError(
            f"`compare`={compare!r} needs measured n, k; fit {fit} was made from curves",
        )
    slots = _slots(request, settings)
    if not slots.acquire(blocking=False):
        raise HTTPException(
            status.HTTP_503_SERVICE_UNAVAILABLE,
            f"{settings.max_previews_in_flight} previews are being rendered "
            "(COATED_MAX_PREVIEWS_IN_FLIGHT); retry shortly",
            headers={"Retry-After": "2"},
        )
    try:
        active = get_preview_renderer(request)
        result = active.render_preview(
            material_from_json(record.material), nk, eta_i=eta_i, size=size,
            compare=compare, environment=environment, differences=False,
            roughness=roughness, mode=mode, coat_roughness=coat_roughness,
        )
    finally:
        slots.release()
    return Response(result.png, media_type="image/png", headers={"Cache-Control": "max-age=3600"})
