"""
Fits
====

-   ``POST /api/v1/fits``: fit a built-in material or inline n, k (JSON).
-   ``GET /api/v1/fits/{fit_id}``: a stored fit.

An uploaded n, k file: :mod:`service.api.routes.fit_uploads`; a fit's downloads and plotted
curves: :mod:`service.api.routes.fit_downloads`.

Fits are content addressed: the same input gives the same id and is served
from the store (200) without refitting; a new fit answers 201.
"""

from __future__ import annotations


from fastapi import APIRouter, Request, Response, status
from fastapi.concurrency import run_in_threadpool

from ...jobs.common import stored_fit
from ...jobs.evaluation import ensure_metrics
from ...jobs.edge_tint import fit_from_colours
from ...jobs.nk import NKFit, fit_nk
from ...schemas import (
    API_PREFIX,
    FitPublic,
    FitRequest,
    fit_public,
)
from ...runtime import CLAIM
from ..deps import (
    FIT_CREATED,
    fit_answer,
    ERROR_RESPONSES,
    FIT_ERROR_RESPONSES,
    NOT_FOUND,
    FitIdPath,
    MetricsQuery,
    RunnerDep,
    SettingsDep,
    SaveRateDep,
    StoreDep,
    WriteAccess,
    note_save,
)

router = APIRouter(prefix=f"{API_PREFIX}/fits", tags=["fits"])


@router.post(
    "",
    response_model=FitPublic,
    status_code=status.HTTP_201_CREATED,
    responses={**FIT_CREATED, **FIT_ERROR_RESPONSES},
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


@router.get("/{fit_id}", response_model=FitPublic, responses={**ERROR_RESPONSES, **NOT_FOUND, **FIT_ERROR_RESPONSES})
async def get_fit(fit_id: FitIdPath, store: StoreDep, runner: RunnerDep) -> FitPublic:
    """A stored fit, with its metrics (evaluated now, once, if they were not yet)."""
    record = await run_in_threadpool(stored_fit, store, fit_id)
    return fit_public(await ensure_metrics(record, store, runner))
