"""
Fits from edited RGB curves
===========================

-   ``POST /api/v1/fits/from-curves``: fit the model to RGB reflectance
    curves (linear ACEScg) at one or more eta_i, alone or as edits of a base
    (a built-in material, a stored fit or inline n, k); stored and
    downloadable like any fit (:mod:`service.jobs.curves`).
-   ``GET /api/v1/fits/{fit_id}/error-map``: Delta E 2000 of a stored fit
    over (angle, eta_i) against what it was fitted to, for the editor's heat
    map.
"""

from __future__ import annotations

import time
from typing import Annotated

from fastapi import APIRouter, Query, Response, status
from fastapi.concurrency import run_in_threadpool

from ...jobs.common import stored_fit
from ...jobs.curves import error_map, fit_from_curves, prepare_curve_fit
from ...jobs.nk import angle_curves
from ...schemas import API_PREFIX, ETA_I_LIMITS, CurveFitPublic, CurveFitRequest, CurvesPublic, ErrorMap, fit_public
from ..deps import (
    CONFLICT,
    ERROR_RESPONSES,
    FIT_ERROR_RESPONSES,
    NOT_FOUND,
    FitIdPath,
    RunnerDep,
    SaveRateDep,
    StoreDep,
    WriteAccess,
    note_save,
)

router = APIRouter(prefix=API_PREFIX, tags=["curves"])

KEEP_BASE_MARGIN_S = 60.0
"""A save on a draft base keeps it for the fit's time limit and this much more."""


@router.post(
    "/fits/from-curves",
    response_model=CurveFitPublic,
    status_code=status.HTTP_201_CREATED,
    responses={
        status.HTTP_200_OK: {"model": CurveFitPublic, "description": "Served from the store"},
        status.HTTP_201_CREATED: {"model": CurveFitPublic, "description": "Fitted and saved"},
        **NOT_FOUND,
        **FIT_ERROR_RESPONSES,
        **CONFLICT,
    },
    dependencies=[WriteAccess],
)
async def create_fit_from_curves(
    request: CurveFitRequest,
    store: StoreDep,
    runner: RunnerDep,
    response: Response,
    rate: SaveRateDep,
    curves_eta_i: Annotated[
        float | None,
        Query(
            ge=ETA_I_LIMITS[0],
            le=ETA_I_LIMITS[1],
            allow_inf_nan=False,
            description="Also answer `GET /fits/{id}/curves` of the fit at this coating index",
        ),
    ] = None,
    curves_samples: Annotated[int, Query(ge=2, le=1024, description="Angles of `curves`")] = 91,
) -> CurveFitPublic:
    """
    Fit the model to edited RGB curves and save the fit under the
    material ``name``. The answer is like ``POST /fits``; ``metrics.model``
    is the mean and max Delta E 2000 of the float16 fit against the curves
    at their samples (``metrics.details.target``: against the whole edited
    target, with a base); with ``curves_eta_i``, ``curves`` holds the fit's
    curves there (one round trip for the editor).
    """
    base = request.base
    fit = await run_in_threadpool(
        lambda: prepare_curve_fit(
            store,
            request.name,
            [c.as_dict() for c in request.curves],
            base_material=base.material if base else None,
            base_fit=base.fit if base else None,
            base_nk=base.nk.arrays() if base and base.nk else None,
            eta_i_range=request.eta_i_range,
            objective=request.objective,
            blend_width=request.blend_width,
            request=request.model_dump(mode="json", exclude={"base", "draft", "live", "start_fit", "expected_version"}),
            draft=request.draft,
            model=request.model,
            live=request.live,
            start_fit=request.start_fit,
            material_id=request.material_id,
        )
    )
    if not request.draft:  # a save: counted against its client's saves per minute (429), unless a repeat
        await note_save(rate, store, fit.material_id, fit.fit_id, fit.name)
    if not request.draft and fit.base_record is not None:
        # A draft base outlives this save's fit (its waits and its run), however short its time to live;
        # once saved, the save keeps it (a saved fit's base never expires).
        await run_in_threadpool(
            store.keep_draft, fit.base_record.id, time.time() + runner.timeout_s + KEEP_BASE_MARGIN_S
        )
    record, created, restored = await fit_from_curves(fit, store, runner, request.expected_version)
    response.status_code = status.HTTP_201_CREATED if created else status.HTTP_200_OK
    response.headers["Location"] = f"{API_PREFIX}/fits/{record.id}"
    curves = None
    if curves_eta_i is not None:
        curves = CurvesPublic(**await run_in_threadpool(angle_curves, record, curves_eta_i, curves_samples))
    return CurveFitPublic(**dict(fit_public(record)), curves=curves, restored_from_bin=restored)


@router.get("/fits/{fit_id}/error-map", response_model=ErrorMap, responses={**ERROR_RESPONSES, **NOT_FOUND})
async def get_error_map(
    fit_id: FitIdPath,
    store: StoreDep,
    angles: Annotated[int, Query(ge=2, le=181, description="Angles evenly from 0 to 90 degrees")] = 46,
    rows: Annotated[int, Query(ge=1, le=101, description="eta_i values evenly over the domain")] = 31,
) -> ErrorMap:
    """
    Delta E 2000 of the fit's float16 model against what it was fitted to:
    the spectral reference (5 nm) of its n, k, or for a curve fit the edited
    target (with a base) or the curves themselves (rows at their eta_i).
    """
    record = await run_in_threadpool(stored_fit, store, fit_id)  # after the query: 422 before 404
    return ErrorMap(**await run_in_threadpool(error_map, record, angles, rows))
