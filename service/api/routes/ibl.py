"""
IBL LUT
=======

``GET /api/v1/ibl-lut``: the split-sum pre-integration table of the model
(:mod:`fitting.shading.lut`, file format in docs/shading.md: magic
``CFIBLUT1``, NdotV x roughness x alpha slices of float32 (A, B, G), CRC-32),
as an attachment ``cf_ibl_lut.cflut``. The bytes come from
:func:`service.downloads.ibl_lut_file` (the on-disk LUT cache, once per
process); the GLSL / HLSL pack downloads carry the lookup that reads it.
"""

from __future__ import annotations

from fastapi import APIRouter, Response, status

from ...downloads import IBL_LUT_FILENAME, ibl_lut_file
from ...schemas import API_PREFIX
from ..deps import ERROR_RESPONSES

router = APIRouter(prefix=API_PREFIX, tags=["downloads"])


@router.get(
    "/ibl-lut",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {
            "content": {"application/octet-stream": {"schema": {"type": "string", "format": "binary"}}},
            "description": "The split-sum LUT file (docs/shading.md)",
        },
        **ERROR_RESPONSES,
    },
)
def ibl_lut() -> Response:
    """The split-sum LUT of the model for image-based lighting, as a file."""
    return Response(
        ibl_lut_file(),
        media_type="application/octet-stream",
        headers={"Content-Disposition": f'attachment; filename="{IBL_LUT_FILENAME}"', "Cache-Control": "max-age=86400"},
    )
