"""
Health
======

``GET /healthz``: answers once the service is ready (store open, fitting
pool started); 503 if the store has become unusable.
"""

from fastapi import APIRouter, HTTPException, status

from ...models import ErrorBody, Health
from ..deps import RunnerDep, SettingsDep, StoreDep

router = APIRouter(tags=["health"])


@router.get(
    "/healthz",
    response_model=Health,
    responses={status.HTTP_503_SERVICE_UNAVAILABLE: {"model": ErrorBody}},
)
def healthz(store: StoreDep, runner: RunnerDep, settings: SettingsDep) -> Health:
    """Readiness: the store answers and the fitting pool is up."""
    try:
        store.check()
    except RuntimeError as error:
        raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, str(error)) from None
    return Health(
        status="ok", fits_in_flight=runner.in_flight, fit_workers=runner.workers,
        max_in_flight=runner.max_in_flight,
    )
