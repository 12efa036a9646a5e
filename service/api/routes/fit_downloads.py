"""
A fit's downloads and curves
============================

-   ``GET /api/v1/fits/{fit_id}/pack``: its download (a pack format) or an export for one coating index.
-   ``GET /api/v1/fits/{fit_id}/curves``: reference, model and baseline RGB
    against the angle, for plotting.

Fitting and reading fits: :mod:`service.api.routes.fits`.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query, Request, Response, status
from fastapi.concurrency import run_in_threadpool

from ...downloads import PACK_CONTENT, export_download, is_export, pack_response
from ...jobs.common import stored_fit
from ...jobs.evaluation import ensure_metrics
from ...jobs.nk import angle_curves
from ...schemas import API_PREFIX, ETA_I_LIMITS, CurvesPublic, DownloadFormat
from ..deps import (
    ERROR_RESPONSES,
    FIT_ERROR_RESPONSES,
    NOT_FOUND,
    CoatRoughnessQuery,
    FitIdPath,
    RoughnessQuery,
    RunnerDep,
    StoreDep,
    WorkingSpaceQuery,
)

router = APIRouter(prefix=f"{API_PREFIX}/fits", tags=["fits"])


@router.get(
    "/{fit_id}/pack",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {"content": PACK_CONTENT, "description": "The download"},
        **NOT_FOUND,
        **FIT_ERROR_RESPONSES,
    },
)
async def get_pack(
    fit_id: FitIdPath,
    store: StoreDep,
    runner: RunnerDep,
    http: Request,
    format: Annotated[
        DownloadFormat,
        Query(description="binary | json | glsl | hlsl, or an export format (`GET /api/v1/domain`: `export_formats`)"),
    ] = "binary",
    eta_i: Annotated[
        float,
        Query(
            ge=ETA_I_LIMITS[0],
            le=ETA_I_LIMITS[1],
            allow_inf_nan=False,
            description="Coating index of an export, [1, 3]",
        ),
    ] = 1.5,
    roughness: RoughnessQuery = 0.2,
    coat_roughness: CoatRoughnessQuery = 0.03,
    working_space: WorkingSpaceQuery = "lin_rec709",
) -> Response:
    """
    The fit as a download: ``binary`` (docs/pack-format.md), ``json``, or a
    ready-to-paste ``glsl`` / ``hlsl`` snippet with the coefficients and the
    evaluation function; or, for one coating index ``eta_i``, an export
    (docs/exports.md): a MaterialX document (``mtlx``: conductor under a
    dielectric coat; ``openpbr``: ``open_pbr_surface``), a Blender script
    (``blender``) or a glTF asset (``gltf``, ``glb``), with ``roughness`` and ``coat_roughness``,
    fitted and written in ``working_space`` (``lin_rec709`` or ``acescg``; ``-acescg`` before the
    suffix), named ``<name>-<id>-eta1.5-rough0.2-coat0.03.<suffix>``.
    """
    if is_export(format):
        return await export_download(
            http.app.state.derived, store, runner, fit_id, format, eta_i, roughness, coat_roughness, working_space
        )
    record = await run_in_threadpool(stored_fit, store, fit_id)  # after the query is validated: 422 before 404
    if format != "binary":  # the JSON and the snippets quote the figures
        record = await ensure_metrics(record, store, runner)
    return await run_in_threadpool(pack_response, [record], format, f"{record.name}-{record.id[:8]}")


@router.get("/{fit_id}/curves", response_model=CurvesPublic, responses={**ERROR_RESPONSES, **NOT_FOUND})
def get_curves(
    fit_id: FitIdPath,
    store: StoreDep,
    eta_i: Annotated[
        float, Query(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False, description="Coating index")
    ] = 1.5,
    samples: Annotated[int, Query(ge=2, le=1024, description="Angles from 0 to 90 degrees")] = 91,
) -> CurvesPublic:
    """
    Linear ACEScg reflectance against the angle theta in the coating, evenly
    from 0 to 90 degrees: the float16 model, the 1 nm spectral reference
    and adjusted Lazanyi (both None for fits without n, k).
    """
    return CurvesPublic(**angle_curves(stored_fit(store, fit_id), eta_i, samples))
