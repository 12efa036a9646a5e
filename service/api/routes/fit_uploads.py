"""
Uploaded n, k
=============

-   ``POST /api/v1/fits/upload``: fit an uploaded n, k file (CSV, JSON, YAML), multipart.

Fits of a built-in material, inline n, k or colours: :mod:`service.api.routes.fits`.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, File, Form, Request, Response, UploadFile, status
from fastapi.concurrency import run_in_threadpool

from ...jobs.nk import NKFit, fit_nk
from ...jobs.uploads import check_coverage
from ...schemas import (
    API_PREFIX,
    DEFAULT_ETA_I_RANGE,
    DEFAULT_MODEL,
    DEFAULT_OBJECTIVE,
    ETA_I_LIMITS,
    FitPublic,
    ModelKind,
    Objective,
)
from ..deps import (
    FIT_CREATED,
    FIT_ERROR_RESPONSES,
    MetricsQuery,
    MinCoverageForm,
    RunnerDep,
    SaveRateDep,
    SettingsDep,
    SingleFormFields,
    StoreDep,
    WriteAccess,
    fit_answer,
    note_save,
)

router = APIRouter(prefix=f"{API_PREFIX}/fits", tags=["fits"])

EtaForm = Annotated[float, Form(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False)]


@router.post(
    "/upload",
    response_model=FitPublic,
    status_code=status.HTTP_201_CREATED,
    responses={**FIT_CREATED, **FIT_ERROR_RESPONSES},
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
