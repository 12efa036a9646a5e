"""
Fits
====

-   ``POST /api/v1/fits``: fit a built-in material or inline n, k (JSON).
-   ``POST /api/v1/fits/upload``: fit an uploaded n, k file (CSV, JSON, YAML), multipart.
-   ``GET /api/v1/fits/{fit_id}``: a stored fit.
-   ``GET /api/v1/fits/{fit_id}/pack``: its download (binary, json, glsl,
    hlsl) or an export for one coating index (mtlx, openpbr, blender, gltf).
-   ``GET /api/v1/fits/{fit_id}/curves``: reference, model and baseline RGB
    against the angle, for plotting.

Fits are content addressed: the same input gives the same id and is served
from the store (200) without refitting; a new fit answers 201.
"""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, File, Form, Query, Response, UploadFile, status
from fastapi.concurrency import run_in_threadpool

from ...downloads import EXPORT_MEDIA_TYPES, PACK_CONTENT, export_response, pack_response, render_export
from ...jobs.common import stored_fit
from ...jobs.nk import NKFit, angle_curves, fit_nk
from ...jobs.uploads import check_coverage
from ...schemas import (API_PREFIX, DEFAULT_ETA_I_RANGE, DEFAULT_OBJECTIVE, ETA_I_LIMITS, PACK_FORMATS,
                        CurvesPublic, FitPublic, FitRequest, Objective, fit_public)
from ...shares import CLAIM
from ...store import FitRecord
from ..deps import (ERROR_RESPONSES, FIT_ERROR_RESPONSES, NOT_FOUND, CoatRoughnessQuery, FitIdPath,
                    MinCoverageForm, RoughnessQuery, RunnerDep, SettingsDep, SingleFormFields, StoredFit,
                    SaveRateDep, StoreDep, WriteAccess)

router = APIRouter(prefix=f"{API_PREFIX}/fits", tags=["fits"])

CREATED = {
    status.HTTP_200_OK: {"model": FitPublic, "description": "Served from the store"},
    status.HTTP_201_CREATED: {"model": FitPublic, "description": "Fitted and saved"},
}
DownloadFormat = Literal[(*PACK_FORMATS, *EXPORT_MEDIA_TYPES)]  # type: ignore[valid-type]
EtaForm = Annotated[float, Form(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False)]


def fit_answer(record: FitRecord, created: bool, response: Response) -> FitPublic:
    """A fit's answer: 201 when just fitted, 200 from the store; Location of the fit."""
    response.status_code = status.HTTP_201_CREATED if created else status.HTTP_200_OK
    response.headers["Location"] = f"{API_PREFIX}/fits/{record.id}"
    return fit_public(record)


@router.post("", response_model=FitPublic, status_code=status.HTTP_201_CREATED,
             responses={**CREATED, **FIT_ERROR_RESPONSES}, dependencies=[WriteAccess])
async def create_fit(request: FitRequest, store: StoreDep, runner: RunnerDep, settings: SettingsDep,
                     response: Response, rate: SaveRateDep) -> FitPublic:
    """
    Fit a built-in material (``{"material": "Au"}``) or inline n, k
    (``{"name": ..., "nk": {"wavelength_nm", "n", "k"}}``) over
    ``eta_i_range``; the answer carries the float16 coefficients, Delta E
    2000 of the model and of adjusted Lazanyi, and timings.
    """
    rate.note(CLAIM.get())  # a save: counted against its client's saves per minute (429 past them)
    runner.check_capacity()
    if request.material is not None:
        fit = await run_in_threadpool(NKFit.library, request.material, request.eta_i_range,
                                      request.objective, settings.metrics_samples, request.model)
    else:
        fit = await run_in_threadpool(
            NKFit.data, (request.name or "uploaded").strip(), request.source, *request.nk.arrays(),
            request.eta_i_range, request.objective, settings.metrics_samples, request.model)
    return fit_answer(*await fit_nk(fit, store, runner), response)


@router.post("/upload", response_model=FitPublic, status_code=status.HTTP_201_CREATED,
             responses={**CREATED, **FIT_ERROR_RESPONSES},
             dependencies=[WriteAccess, SingleFormFields])
async def upload_fit(
    file: Annotated[UploadFile, File(description="n, k as CSV, JSON or refractiveindex.info YAML")],
    store: StoreDep, runner: RunnerDep, settings: SettingsDep, response: Response, rate: SaveRateDep,
    format: Annotated[str | None, Form(pattern=r"^(csv|json|yaml|yml)$",
                                       description="Default: from the file name")] = None,
    name: Annotated[str | None, Form(min_length=1, max_length=200, pattern=r"\S")] = None,
    eta_i_min: EtaForm = DEFAULT_ETA_I_RANGE[0],
    eta_i_max: EtaForm = DEFAULT_ETA_I_RANGE[1],
    objective: Annotated[Objective, Form()] = DEFAULT_OBJECTIVE,
    min_coverage: MinCoverageForm = None,
) -> FitPublic:
    """
    Fit an uploaded n, k file (size limit: COATED_MAX_UPLOAD_BYTES). The
    file is parsed, never stored or executed as given; the fit keeps its
    n, k as numbers. The data must cover 90% of 360-830 nm, or `min_coverage` when it asks more.
    """
    rate.note(CLAIM.get())
    runner.check_capacity()
    data = await file.read()
    fit = await run_in_threadpool(NKFit.upload, data, file.filename or "", format, name,
                                  (eta_i_min, eta_i_max), objective, settings.metrics_samples)
    check_coverage(fit.nk, min_coverage)
    return fit_answer(*await fit_nk(fit, store, runner), response)


@router.get("/{fit_id}", response_model=FitPublic, responses={**ERROR_RESPONSES, **NOT_FOUND})
def get_fit(record: StoredFit) -> FitPublic:
    """A stored fit."""
    return fit_public(record)


@router.get("/{fit_id}/pack", response_class=Response, responses={
    status.HTTP_200_OK: {"content": PACK_CONTENT, "description": "The download"},
    **NOT_FOUND, **FIT_ERROR_RESPONSES,
})
async def get_pack(
    fit_id: FitIdPath, store: StoreDep, runner: RunnerDep,
    format: Annotated[DownloadFormat, Query(
        description="binary | json | glsl | hlsl | mtlx | openpbr | blender | gltf")] = "binary",
    eta_i: Annotated[float, Query(
        ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False,
        description="Coating index of an export (mtlx, openpbr, blender, gltf), [1, 3]")] = 1.5,
    roughness: RoughnessQuery = 0.2, coat_roughness: CoatRoughnessQuery = 0.03,
) -> Response:
    """
    The fit as a download: ``binary`` (docs/pack-format.md), ``json``, or a
    ready-to-paste ``glsl`` / ``hlsl`` snippet with the coefficients and the
    evaluation function; or, for one coating index ``eta_i``, an export
    (docs/exports.md): a MaterialX document (``mtlx``: conductor under a
    dielectric coat; ``openpbr``: ``open_pbr_surface``), a Blender script
    (``blender``) or a glTF asset (``gltf``), with ``roughness`` and
    ``coat_roughness``; named ``<name>-<id>-eta1.5-rough0.2-coat0.03.<suffix>``.
    """
    record = stored_fit(store, fit_id)  # after the query is validated: 422 before 404
    stem = f"{record.name}-{record.id[:8]}"
    if format in EXPORT_MEDIA_TYPES:
        # An export fits its tool's values (up to about a second of CPU): a job in the
        # fitting pool, with its CPU limit and timeout, shared by identical requests.
        body = await runner.once(
            f"export {record.id} {format} {eta_i!r} {roughness!r} {coat_roughness!r}",
            lambda: runner.run(render_export, record, format, eta_i, roughness, coat_roughness, cost_s=1.0))
        return export_response(body, format, eta_i, stem, roughness, coat_roughness)
    return pack_response([record], format, stem)


@router.get("/{fit_id}/curves", response_model=CurvesPublic, responses={**ERROR_RESPONSES, **NOT_FOUND})
def get_curves(
    fit_id: FitIdPath, store: StoreDep,
    eta_i: Annotated[float, Query(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False,
                                  description="Coating index")] = 1.5,
    samples: Annotated[int, Query(ge=2, le=1024, description="Angles from 0 to 90 degrees")] = 91,
) -> CurvesPublic:
    """
    Linear ACEScg reflectance against the angle theta in the coating, evenly
    from 0 to 90 degrees: the float16 model, the 1 nm spectral reference
    and adjusted Lazanyi (both None for fits without n, k).
    """
    return CurvesPublic(**angle_curves(stored_fit(store, fit_id), eta_i, samples))
