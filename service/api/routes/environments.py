"""
Prefiltered environments
========================

``GET /api/v1/environments/{environment}/prefiltered``: a preview
environment (``white_sky``, ``studio``, ``outdoor``: ``cf_environment.glsl``)
prefiltered per roughness for the split sum (Karis 2013), for the editor's
WebGL preview of rough and coated spheres; the same slices the server's own
rough preview uses (:func:`preview_shaders.rough.prefiltered_environment`).

The body is little-endian float32 RGB (linear ACEScg), row-major
``[slice][row][column][channel]``:

-   ``X-Texture-Layers`` slices at roughness j / (layers - 1) (9: 0, 1/8, ..., 1);
-   ``X-Texture-Height`` rows from straight up (row 0) to straight down, at
    the texel centres of theta in [0, pi];
-   ``X-Texture-Width`` columns over the azimuth, u = 0.5 towards -z
    (``cf_equirect_uv`` in ``cf_prefiltered_environment.glsl``).

The environment is drawn in a process of the render pool
(:class:`service.runtime.previews.PreviewRunner`, on its renderer's GL thread; 503
without a GL driver) and prefiltered once per process (cached on disk: the
first request of a machine takes seconds, later ones milliseconds).
"""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Path, Response, status

from preview_shaders.preview import ENVIRONMENTS

from ...jobs.textures import environment_texture
from ...schemas import API_PREFIX, ErrorBody
from ..deps import ERROR_RESPONSES, PreviewsDep

router = APIRouter(prefix=API_PREFIX, tags=["preview"])

__all__ = ["router"]


@router.get(
    "/environments/{environment}/prefiltered",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {
            "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}},
            "description": "float32 RGB [slice][row][column][channel]",
        },
        **ERROR_RESPONSES,
        status.HTTP_503_SERVICE_UNAVAILABLE: {
            "model": ErrorBody,
            "description": ("No GL on this machine, or too many textures waiting for the render pool (Retry-After)"),
        },
        status.HTTP_504_GATEWAY_TIMEOUT: {
            "model": ErrorBody,
            "description": ("Not ready within COATED_PREVIEW_TIMEOUT_S (Retry-After)"),
        },
    },
)
async def get_prefiltered_environment(
    environment: Annotated[Literal[ENVIRONMENTS], Path(description="A preview environment")],  # type: ignore[valid-type]
    previews: PreviewsDep,
) -> Response:
    """The environment prefiltered at roughness 0, 1/8, ..., 1 as float32 RGB slices (see the headers)."""
    body, headers = await previews.texture(("environment", environment), environment_texture, environment)
    return Response(body, media_type="application/octet-stream", headers=headers)
