"""
Dependencies
============

``Annotated`` dependencies shared by the routers:

-   :data:`SettingsDep`: the app's :class:`service.config.Settings`.
-   :data:`StoreDep`: the app's :class:`service.store.Store`.
-   :data:`RunnerDep`: the app's :class:`service.fitting_jobs.FitRunner`.
-   :data:`WriteAccess`: the bearer-token check of the write endpoints
    (a no-op unless the settings require a token).
-   :func:`fit_errors`: a context manager that turns the fitting core's
    ``ValueError`` into 422 and the runner's refusals into 503/504.
-   :data:`ERROR_RESPONSES`: the error answers for the OpenAPI document.
"""

from __future__ import annotations

import contextlib
import hmac
from typing import Annotated, Iterator

from fastapi import Depends, HTTPException, Request, status
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer

from ..config import Settings
from ..fitting_jobs import FitRunner, FitTimeout, Overloaded, WorkerLost
from ..models import ErrorBody
from ..store import Store

__all__ = [
    "SettingsDep",
    "StoreDep",
    "RunnerDep",
    "WriteAccess",
    "fit_errors",
    "ERROR_RESPONSES",
    "FIT_ERROR_RESPONSES",
]


def get_settings(request: Request) -> Settings:
    return request.app.state.settings


def get_store(request: Request) -> Store:
    return request.app.state.store


def get_runner(request: Request) -> FitRunner:
    return request.app.state.runner


SettingsDep = Annotated[Settings, Depends(get_settings)]
StoreDep = Annotated[Store, Depends(get_store)]
RunnerDep = Annotated[FitRunner, Depends(get_runner)]

_bearer = HTTPBearer(auto_error=False, description="COATED_API_TOKEN, when the service requires one")


def require_write_access(
    request: Request,
    settings: SettingsDep,
    credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(_bearer)],
) -> None:
    """
    Refuse a cross-site write from a browser, and a write without the
    configured bearer token (when one is required).

    A browser names the page that sends a request in ``Origin``; a write
    from a page of another site (a multipart upload needs no CORS
    preflight) is refused unless that origin is in ``cors_origins``.
    Pipelines (curl, scripts) send no ``Origin``.
    """
    origin = request.headers.get("origin")
    if origin is not None:
        own = f"{request.url.scheme}://{request.headers.get('host', '')}"
        if origin != own and origin not in settings.cors_origins:
            raise HTTPException(
                status.HTTP_403_FORBIDDEN,
                f"cross-site writes are refused: `Origin` {origin!r} is neither this service "
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


@contextlib.contextmanager
def fit_errors() -> Iterator[None]:
    """Map the core's and the runner's exceptions to HTTP answers."""
    try:
        yield
    except ValueError as error:
        raise HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, str(error)) from None
    except Overloaded as error:
        raise HTTPException(
            status.HTTP_503_SERVICE_UNAVAILABLE, str(error),
            headers={"Retry-After": str(error.retry_after)},
        ) from None
    except WorkerLost as error:
        raise HTTPException(
            status.HTTP_503_SERVICE_UNAVAILABLE, str(error), headers={"Retry-After": "1"}
        ) from None
    except FitTimeout as error:
        raise HTTPException(status.HTTP_504_GATEWAY_TIMEOUT, str(error)) from None


def _error(description: str) -> dict:
    return {"model": ErrorBody, "description": description}


ERROR_RESPONSES = {
    status.HTTP_422_UNPROCESSABLE_CONTENT: _error("A field broke a rule (named in `detail`)"),
}
FIT_ERROR_RESPONSES = {
    **ERROR_RESPONSES,
    status.HTTP_401_UNAUTHORIZED: _error("Missing or wrong bearer token (when required)"),
    status.HTTP_403_FORBIDDEN: _error("A cross-site write from a browser (Origin of another site)"),
    status.HTTP_413_CONTENT_TOO_LARGE: _error("The body is larger than the limit"),
    status.HTTP_503_SERVICE_UNAVAILABLE: _error("Too many fits in flight; see Retry-After"),
    status.HTTP_504_GATEWAY_TIMEOUT: _error("The fit ran past its time limit"),
}
