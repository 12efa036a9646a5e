"""
Dependencies
============

``Annotated`` dependencies shared by the routers:

-   :data:`SettingsDep`, :data:`StoreDep`, :data:`RunnerDep`: the app's
    settings, store and fitting pool. These lookups, and :data:`WriteAccess`,
    are ``async``: FastAPI runs a plain ``def`` dependency in a worker
    thread, two thread hops a request that took most of a kept export's
    download (:data:`StoredFit` reads the store and stays a plain ``def``).
-   :data:`FitIdPath`, :data:`MaterialIdPath`, :data:`RoughnessQuery`,
    :data:`CoatRoughnessQuery`, :data:`WorkingSpaceQuery`, :data:`MinCoverageForm`, :data:`MetricsQuery`: shared
    parameters.
-   :data:`StoredFit`: the stored fit named by the path's ``fit_id`` (404
    when it is not stored), read in a worker thread.
-   :data:`WriteAccess`: the cross-site and bearer-token checks of the write
    endpoints.
-   :data:`SingleFormFields`: a form field given twice (two ``file`` parts)
    is refused (422), not resolved silently to the last.
-   :data:`SaveRateDep`: the app's saves per client per minute
    (:class:`service.runtime.shares.SaveRate`); a save route counts itself there
    once its input is valid (:func:`note_save`: a repeat of the material's
    latest version adds nothing and is neither counted nor refused).
-   :data:`PreviewsDep`: the app's render pool (previews and GL textures,
    :class:`service.runtime.previews.PreviewRunner`).
-   :data:`ERROR_RESPONSES`, :data:`FIT_ERROR_RESPONSES`,
    :data:`NOT_FOUND`: the error answers for the OpenAPI document.
-   :func:`fit_answer` and :data:`FIT_CREATED`: a fit's answer (201 when just
    fitted, 200 from the store, its Location), for the routes that fit.
"""

from __future__ import annotations

import hmac
from typing import Annotated, Literal

from fastapi import Depends, Form, HTTPException, Path, Query, Request, Response, status
from fastapi.concurrency import run_in_threadpool
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

from ..config import Settings
from ..jobs.common import stored_fit
from ..runtime import CLAIM, FitRunner, PreviewRunner, SaveRate
from ..schemas import API_PREFIX, FIT_ID_PATTERN, MATERIAL_ID_PATTERN, ErrorBody, FitPublic, WorkingSpace, fit_public
from ..store import FitRecord, Store
from ..store.queries import summary_text

__all__ = [
    "SettingsDep",
    "StoreDep",
    "RunnerDep",
    "FitIdPath",
    "MaterialIdPath",
    "RoughnessQuery",
    "CoatRoughnessQuery",
    "WorkingSpaceQuery",
    "MinCoverageForm",
    "MetricsQuery",
    "StoredFit",
    "WriteAccess",
    "SingleFormFields",
    "PreviewsDep",
    "SaveRateDep",
    "note_save",
    "ERROR_RESPONSES",
    "FIT_ERROR_RESPONSES",
    "NOT_FOUND",
    "CONFLICT",
    "FIT_CREATED",
    "fit_answer",
]


async def get_settings(request: Request) -> Settings:
    return request.app.state.settings


async def get_store(request: Request) -> Store:
    return request.app.state.store


async def get_runner(request: Request) -> FitRunner:
    return request.app.state.runner


async def get_previews(request: Request) -> PreviewRunner:
    return request.app.state.previews


async def get_save_rate(request: Request) -> SaveRate:
    return request.app.state.save_rate


SettingsDep = Annotated[Settings, Depends(get_settings)]
StoreDep = Annotated[Store, Depends(get_store)]
RunnerDep = Annotated[FitRunner, Depends(get_runner)]
PreviewsDep = Annotated[PreviewRunner, Depends(get_previews)]
SaveRateDep = Annotated[SaveRate, Depends(get_save_rate)]


async def note_save(rate: SaveRate, store: Store, material_id: str, fit_id: str, name: str) -> None:
    """
    Count a save of fit ``fit_id`` as ``name`` under ``material_id``
    against its client's saves per minute (429 past them), unless it
    repeats what the material holds now (that fit its latest, that name, not
    in the bin): such a save adds no version (the store answers the
    existing one), so it is neither counted nor refused.
    """
    row = await run_in_threadpool(store.material, material_id)
    if row is not None and row.latest_fit_id == fit_id and row.deleted_at is None and row.name == summary_text(name):
        return
    rate.note(CLAIM.get())


FitIdPath = Annotated[str, Path(pattern=FIT_ID_PATTERN, description="32 lowercase hex digits")]
MaterialIdPath = Annotated[
    str, Path(pattern=MATERIAL_ID_PATTERN, description="A library name or a saved material's id")
]
RoughnessQuery = Annotated[
    float,
    Query(
        ge=0.0,
        le=1.0,
        allow_inf_nan=False,
        description=("The metal's perceptual roughness of an export, [0, 1] (the editor's preview value)"),
    ),
]
CoatRoughnessQuery = Annotated[
    float,
    Query(
        ge=0.0,
        le=1.0,
        allow_inf_nan=False,
        description=("The coat's perceptual roughness of an export, [0, 1] (the editor's preview value)"),
    ),
]
MetricsQuery = Annotated[
    Literal["solve", "full"],
    Query(
        description=(
            "`solve` (default): answer as soon as the fit is saved, with what its solve measured "
            "(`metrics.evaluated` false until its evaluation on the metrics grid has run, after the answer); "
            "`full`: wait for that evaluation (the figure, Delta E of the model and the baselines)"
        )
    ),
]
WorkingSpaceQuery = Annotated[
    WorkingSpace,
    Query(description=("lin_rec709 | acescg: the working space an export is fitted and written in (docs/exports.md)")),
]
MinCoverageForm = Annotated[
    float | None,
    Form(
        ge=0.0,
        le=1.0,
        allow_inf_nan=False,
        description=(
            "Least covered fraction of 360-830 nm to accept, in [0.9, 1] (default 0.9, the service's own "
            "rule; a higher value refuses data the service would fit)"
        ),
    ),
]


def get_stored_fit(fit_id: FitIdPath, store: StoreDep) -> FitRecord:
    """The record of the path's ``fit_id`` (LookupError -> 404)."""
    return stored_fit(store, fit_id)


StoredFit = Annotated[FitRecord, Depends(get_stored_fit)]

_bearer = HTTPBearer(auto_error=False, description="COATED_API_TOKEN, when the service requires one")


async def require_write_access(
    request: Request,
    settings: SettingsDep,
    credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(_bearer)],
) -> None:
    """
    Refuse a cross-site write from a browser, and a write without the
    configured bearer token (when one is required).

    A browser names the page that sends a request in ``Origin``; a write
    from a page of another site (a multipart upload needs no CORS
    preflight) is refused unless that origin is in ``cors_origins``. The
    ``Host`` it is compared with has passed the allow-list
    (:class:`service.api.middleware.HostAllowList`), so a DNS-rebinding page
    (whose ``Host`` is its own name) never gets this far. Pipelines (curl,
    scripts) send no ``Origin``.
    """
    origin = request.headers.get("origin")
    if origin is not None:
        own = f"{request.url.scheme}://{request.headers.get('host', '')}"
        if origin != own and origin not in settings.cors_origins:
            raise HTTPException(
                status.HTTP_403_FORBIDDEN,
                f"cross-site writes are refused: `Origin` {origin[:100]!r} is neither this service "
                f"({own}) nor in COATED_CORS_ORIGINS",
            )
    if not settings.token_required:
        return
    expected = settings.api_token.get_secret_value().encode() if settings.api_token else b""
    given = credentials.credentials.encode() if credentials else b""
    if not credentials or not hmac.compare_digest(given, expected):
        raise HTTPException(
            status.HTTP_401_UNAUTHORIZED,
            "this endpoint needs the header `Authorization: Bearer <token>` with the "
            "service's token (COATED_API_TOKEN)",
            headers={"WWW-Authenticate": "Bearer"},
        )


WriteAccess = Depends(require_write_access)


async def refuse_repeated_form_fields(request: Request) -> None:
    """ValueError (422) naming the first form field given more than once."""
    form = await request.form()  # parsed once for the route's fields: cached
    repeated = sorted({key for key in form.keys() if len(form.getlist(key)) > 1})
    if repeated:
        raise ValueError(
            f"each form field must be given once, got {len(form.getlist(repeated[0]))} `{repeated[0][:40]}` parts"
        )


SingleFormFields = Depends(refuse_repeated_form_fields)


def _error(description: str) -> dict:
    return {"model": ErrorBody, "description": description}


ERROR_RESPONSES = {
    status.HTTP_400_BAD_REQUEST: _error("The `Host` is not in COATED_ALLOWED_HOSTS"),
    status.HTTP_422_UNPROCESSABLE_CONTENT: _error("A field broke a rule (named in `detail`)"),
    status.HTTP_503_SERVICE_UNAVAILABLE: _error("The store is unavailable, or the service is busy; see Retry-After"),
}
NOT_FOUND = {status.HTTP_404_NOT_FOUND: _error("Not stored")}
CONFLICT = {
    status.HTTP_409_CONFLICT: _error(
        "`expected_version` is not the material's version, or the "
        "material was renamed or moved to the bin since: the "
        "message names what changed; nothing was saved"
    )
}
FIT_ERROR_RESPONSES = {
    **ERROR_RESPONSES,
    status.HTTP_401_UNAUTHORIZED: _error("Missing or wrong bearer token (when required)"),
    status.HTTP_403_FORBIDDEN: _error("A cross-site write from a browser (Origin of another site)"),
    status.HTTP_408_REQUEST_TIMEOUT: _error("The body arrived slower than COATED_BODY_TIMEOUT_S"),
    status.HTTP_413_CONTENT_TOO_LARGE: _error("The body is larger than the limit"),
    status.HTTP_429_TOO_MANY_REQUESTS: _error("A save past COATED_SAVES_PER_CLIENT_PER_MINUTE; see Retry-After"),
    status.HTTP_503_SERVICE_UNAVAILABLE: _error(
        "Too many fits in flight, a worker died twice, or the store is unavailable; see Retry-After"
    ),
    status.HTTP_504_GATEWAY_TIMEOUT: _error(
        "The fit ran past its time limit; it goes on, retry after Retry-After for its result"
    ),
    status.HTTP_507_INSUFFICIENT_STORAGE: _error("The store is full; nothing was fitted"),
}


# A fit's answer (POST /fits, /fits/upload): 201 when just fitted, 200 from the store.
FIT_CREATED = {
    status.HTTP_200_OK: {"model": FitPublic, "description": "Served from the store"},
    status.HTTP_201_CREATED: {"model": FitPublic, "description": "Fitted and saved"},
}


def fit_answer(record: FitRecord, created: bool, response: Response) -> FitPublic:
    """A fit's answer: 201 when just fitted, 200 from the store; Location of the fit."""
    response.status_code = status.HTTP_201_CREATED if created else status.HTTP_200_OK
    response.headers["Location"] = f"{API_PREFIX}/fits/{record.id}"
    return fit_public(record)
