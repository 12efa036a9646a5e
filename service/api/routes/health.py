"""
Health and domain
=================

-   ``GET /healthz``: answers once the service is ready (store open, fitting
    pool started), says whether the store can take a save now and which
    store it is (kind, schema version, this replica's connections); 503
    with Retry-After and the reason when this replica cannot serve another
    client: the store cannot be read (the database restarting), every
    connection it accepts has a request in progress, or the fitting pool
    could not start a worker process (three tries of a job; each probe then
    tries again in the background, 200 once a worker starts). Cheap (no integrity
    scan, no write), its store probe runs in a thread of its own, so it
    answers while fits run, and its connection has a reserve of its own
    (:mod:`service.runtime.server`), so it answers past every bound.
-   ``GET /api/v1/domain``: the eta_i limits, the default domain and the
    other constants a client checks before sending, from the core, and
    every registered export format and model kind (a kind with its
    parameters and the GLSL the browser's preview includes to draw it).
"""

import asyncio
from concurrent.futures import ThreadPoolExecutor

from fastapi import APIRouter, HTTPException, Request, status

from fitting.fits.curves_input import CURVE_MAX_COUNT, CURVE_MAX_SAMPLES, CURVE_MIN_SAMPLES
from fitting.domain import DEFAULT_MIN_COVERAGE, VISIBLE_RANGE_NM
from fitting.exports.formats import describe_export_formats
from fitting.fits.settings import OBJECTIVES
from fitting.models.kinds import DEFAULT_MODEL, MODEL_KINDS
from fitting.optics.library import LIBRARY_NAMES
from preview_shaders.kinds import preview_model_source

from ...schemas import (
    API_PREFIX,
    DEFAULT_ETA_I_RANGE,
    DEFAULT_OBJECTIVE,
    ETA_I_LIMITS,
    MAX_NK_SAMPLES,
    PACK_FORMATS,
    Domain,
    ErrorBody,
    Health,
    ModelKindPublic,
)
from ...store import Store
from ..deps import PreviewsDep, RunnerDep, SettingsDep, StoreDep

router = APIRouter(tags=["health"])


# Its own thread: the probe never queues behind the requests' thread work.
_PROBE_THREAD = ThreadPoolExecutor(1, thread_name_prefix="healthz")


def _probe(store: Store) -> tuple[str | None, dict]:
    store.ping()  # StoreError -> 503 + Retry-After
    return store.writable(), store.describe()


@router.get("/healthz", response_model=Health, responses={status.HTTP_503_SERVICE_UNAVAILABLE: {"model": ErrorBody}})
async def healthz(request: Request, store: StoreDep, runner: RunnerDep, previews: PreviewsDep) -> Health:
    """Readiness: the store answers, a new client's connection would be served; whether a save can be written."""
    connections = getattr(request.app.state, "connections", None)  # set by the server (none in-process)
    held = connections.held() if connections is not None else None
    if held:
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, f"not ready: {held}", headers={"Retry-After": "2"})
    if runner.cannot_start is not None:  # no fit could run: tried again in the background, 200 once it starts
        runner.retry_start()
        raise HTTPException(
            status.HTTP_503_SERVICE_UNAVAILABLE, f"not ready: {runner.cannot_start}", headers={"Retry-After": "2"}
        )
    problem, described = await asyncio.get_running_loop().run_in_executor(_PROBE_THREAD, _probe, store)
    return Health(
        status="ok",
        fits_in_flight=runner.in_flight,
        fit_workers=runner.workers,
        max_in_flight=runner.max_in_flight,
        store_writable=problem is None,
        store_problem=problem,
        pool_restarts=runner.restarts,
        previews_in_flight=previews.previews_in_flight,
        store=described,
    )


def describe_model_kinds() -> list[ModelKindPublic]:
    """Every registered model kind as the browser draws it (its preview's GLSL generated from the registry)."""
    return [
        ModelKindPublic(
            name=kind.name,
            description=kind.description,
            parameters=list(kind.parameters),
            max_degree=kind.max_degree,
            split_sum=kind.split_sum,
            live_solver=kind.live_solver,
            glsl=preview_model_source(kind, inline=True),
        )
        for kind in MODEL_KINDS.values()
    ]


def current_domain() -> Domain:
    """The rules and defaults, with the export formats and model kinds registered now (a plugin's among them)."""
    return Domain(
        eta_i_limits=list(ETA_I_LIMITS),
        default_eta_i_range=list(DEFAULT_ETA_I_RANGE),
        objectives=list(OBJECTIVES),
        default_objective=DEFAULT_OBJECTIVE,
        library=list(LIBRARY_NAMES),
        pack_formats=list(PACK_FORMATS),
        export_formats=describe_export_formats(),
        model_kinds=describe_model_kinds(),
        default_model=DEFAULT_MODEL,
        curve_samples=[CURVE_MIN_SAMPLES, CURVE_MAX_SAMPLES],
        max_curves=CURVE_MAX_COUNT,
        max_nk_samples=MAX_NK_SAMPLES,
        visible_range_nm=list(VISIBLE_RANGE_NM),
        min_coverage=DEFAULT_MIN_COVERAGE,
    )


@router.get(f"{API_PREFIX}/domain", response_model=Domain)
async def domain(settings: SettingsDep) -> Domain:
    """The rules and defaults of the API's inputs (the editor reads them instead of repeating them)."""
    return current_domain().model_copy(update={"draft_ttl_s": settings.draft_ttl_s})
