"""
Imports
=======

-   ``POST /api/v1/fits/import``: a binary pack, its JSON view, or an export
    of this service (glTF, GLB, MaterialX, OpenPBR, Blender script), multipart,
    read back to its fit: the stored fit it names (200), or a new fit of its
    float16 model (201); a damaged file 422 (:mod:`service.jobs.imports`).
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, File, Response, UploadFile, status

from ...jobs.imports import import_fit
from ...schemas import API_PREFIX, FitPublic, fit_public
from ..deps import FIT_ERROR_RESPONSES, SingleFormFields, StoreDep, WriteAccess

router = APIRouter(prefix=f"{API_PREFIX}/fits", tags=["fits"])

CREATED = {
    status.HTTP_200_OK: {"model": FitPublic, "description": "The stored fit the file names"},
    status.HTTP_201_CREATED: {"model": FitPublic, "description": "A new fit of the file's model, saved"},
}


@router.post(
    "/import",
    response_model=FitPublic,
    status_code=status.HTTP_201_CREATED,
    responses={**CREATED, **FIT_ERROR_RESPONSES},
    dependencies=[WriteAccess, SingleFormFields],
)
async def import_fit_file(
    file: Annotated[
        UploadFile,
        File(
            description=(
                "A binary pack, its JSON view, or an export of this service: .gltf, .glb, .mtlx, "
                ".openpbr.mtlx, Blender .py"
            )
        ),
    ],
    store: StoreDep,
    response: Response,
) -> FitPublic:
    """
    Read a pack or an export back to its fit (docs/exports.md): checked
    (checksum, version, values; a damaged file is refused with 422 naming
    what is wrong), then the stored fit it names (200), or a new fit of its
    float16 model (201). Nothing in the file is run.
    """
    data = await file.read()
    record, created = await import_fit(store, data)
    response.status_code = status.HTTP_201_CREATED if created else status.HTTP_200_OK
    response.headers["Location"] = f"{API_PREFIX}/fits/{record.id}"
    return fit_public(record)
