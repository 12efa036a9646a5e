"""
Fits
====

-   ``POST /api/v1/fits``: fit a built-in material or inline n, k (JSON).
-   ``POST /api/v1/fits/upload``: fit an uploaded n, k file (CSV, JSON, YAML), multipart.
-   ``GET /api/v1/fits/{fit_id}``: a stored fit.
-   ``GET /api/v1/fits/{fit_id}/pack``: its download (a pack format) or an export for one coating index.
-   ``GET /api/v1/fits/{fit_id}/curves``: reference, model and baseline RGB
    against the angle, for plotting.

Fits are content addressed: the same input gives the same id and is served
from the store (200) without refitting; a new fit answers 201.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, File, Form, Query, Request, Response, UploadFile, status
from fastapi.concurrency import run_in_threadpool

from ...downloads import PACK_CONTENT, export_download, is_export, pack_response
from ...jobs.common import stored_fit
from ...jobs.evaluation import ensure_metrics
from ...jobs.edge_tint import fit_from_colours
from ...jobs.nk import NKFit, angle_curves, fit_nk
from ...jobs.uploads import check_coverage
from ...schemas import (
    API_PREFIX,
    DEFAULT_ETA_I_RANGE,
    DEFAULT_MODEL,
    DEFAULT_OBJECTIVE,
    ETA_I_LIMITS,
    CurvesPublic,
    DownloadFormat,
    FitPublic,
    FitRequest,
    ModelKind,
    Objective,
    fit_public,
)
from ...runtime import CLAIM
from ...store import FitRecord
from ..deps import (
    ERROR_RESPONSES,
    FIT_ERROR_RESPONSES,
    NOT_FOUND,
    CoatRoughnessQuery,
    FitIdPath,
    MetricsQuery,
    MinCoverageForm,
    RoughnessQuery,
    WorkingSpaceQuery,
    RunnerDep,
    SettingsDep,
    SingleFormFields,
    SaveRateDep,
    StoreDep,
    WriteAccess,
    note_save,
)

router = APIRouter(prefix=f"{API_PREFIX}/fits", tags=["fits"])

CREATED = {
    status.HTTP_200_OK: {"model": FitPublic, "description": "Served from the store"},
    status.HTTP_201_CREATED: {"model": FitPublic, "description": "Fitted and saved"},
}
EtaForm = Annotated[float, Form(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False)]


def fit_answer(record: FitRecord, created: bool, response: Response) -> FitPublic:
    """A fit's answer: 201 when just fitted, 200 from the store; Location of the fit."""
    response.status_code = status.HTTP_201_CREATED if created else status.HTTP_200_OK
    response.headers["Location"] = f"{API_PREFIX}/fits/{record.id}"
    return fit_public(record)


@router.post(
    "",
    response_model=FitPublic,
    status_code=status.HTTP_201_CREATED,
    responses={**CREATED, **FIT_ERROR_RESPONSES},
    dependencies=[WriteAccess],
)
async def create_fit(
    request: FitRequest,
    store: StoreDep,
    runner: RunnerDep,
    settings: SettingsDep,
    response: Response,
    http: Request,
    rate: SaveRateDep,
    metrics: MetricsQuery = "solve",
) -> FitPublic:
    """
    Fit a built-in material (``{"material": "Au"}``), inline n, k (``{"name": ..., "nk": {"wavelength_nm",
    "n", "k"}}``) or F0 and F82 tint (``{"name", "f0", "f82", "space"}``: an ``rgb-conductor``) over
    ``eta_i_range``; the answer carries the float16 coefficients, what the solve measured, and timings;
    Delta E 2000 of the model and of adjusted Lazanyi on the metrics grid with ``?metrics=full`` (else
    later: ``GET /fits/{id}``).
    """
    if request.f0 is not None:  # F0 and F82 colours: n, k from them, no fit to run
        rate.note(CLAIM.get())  # a save: counted against its client's saves per minute (429)
        return fit_answer(*await fit_from_colours(store, request), response)
    runner.check_capacity()
    if request.material is not None:
        fit = await run_in_threadpool(
            NKFit.library,
            request.material,
            request.eta_i_range,
            request.objective,
            settings.metrics_samples,
            request.model,
        )
    else:
        fit = await run_in_threadpool(
            NKFit.data,
            (request.name or "uploaded").strip(),
            request.source,
            *request.nk.arrays(),
            request.eta_i_range,
            request.objective,
            settings.metrics_samples,
            request.model,
        )
    await note_save(rate, store, fit.material_id, fit.fit_id, fit.name)  # a repeat: not counted
    return fit_answer(*await fit_nk(fit, store, runner, http.app.state.evaluations, metrics == "full"), response)


@router.post(
    "/upload",
    response_model=FitPublic,
    status_code=status.HTTP_201_CREATED,
    responses={**CREATED, **FIT_ERROR_RESPONSES},
    dependencies=[WriteAccess, SingleFormFields],
)
async def upload_fit(
    file: Annotated[UploadFile, File(description="n, k as CSV, JSON or refractiveindex.info YAML")],
    store: StoreDep,
    runner: RunnerDep,
    settings: SettingsDep,
    response: Response,
    http: Request,
    rate: SaveRateDep,
    format: Annotated[
        str | None, Form(pattern=r"^(csv|json|yaml|yml)$", description="Default: from the file name")
    ] = None,
    name: Annotated[str | None, Form(min_length=1, max_length=200, pattern=r"\S")] = None,
    eta_i_min: EtaForm = DEFAULT_ETA_I_RANGE[0],
    eta_i_max: EtaForm = DEFAULT_ETA_I_RANGE[1],
    objective: Annotated[Objective, Form()] = DEFAULT_OBJECTIVE,
    model: Annotated[ModelKind, Form(description="The model kind to fit")] = DEFAULT_MODEL,
    min_coverage: MinCoverageForm = None,
    metrics: MetricsQuery = "solve",
) -> FitPublic:
    """
    Fit an uploaded n, k file (size limit: COATED_MAX_UPLOAD_BYTES), parsed, never stored or executed as given
    (the fit keeps its n, k as numbers); it must cover 90% of 360-830 nm, or `min_coverage` when it asks more.
    """
    runner.check_capacity()
    data = await file.read()
    fit = await run_in_threadpool(
        NKFit.upload,
        data,
        file.filename or "",
        format,
        name,
        (eta_i_min, eta_i_max),
        objective,
        settings.metrics_samples,
        model,
    )
    check_coverage(fit.nk, min_coverage)
    await note_save(rate, store, fit.material_id, fit.fit_id, fit.name)
    return fit_answer(*await fit_nk(fit, store, runner, http.app.state.evaluations, metrics == "full"), response)


@router.get("/{fit_id}", response_model=FitPublic, responses={**ERROR_RESPONSES, **NOT_FOUND, **FIT_ERROR_RESPONSES})
async def get_fit(fit_id: FitIdPath, store: StoreDep, runner: RunnerDep) -> FitPublic:
    """A stored fit, with its metrics (evaluated now, once, if they were not yet)."""
    record = await run_in_threadpool(stored_fit, store, fit_id)
    return fit_public(await ensure_metrics(record, store, runner))


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
