"""
Error answers
=============

The one place where exceptions become HTTP answers; every 4xx and 5xx is
``{"detail": ..., "errors": [...]}`` (:class:`service.schemas.ErrorBody`):

=====================================  ======================================
``RequestValidationError``             422, naming each field and rule
``ValueError`` (the core's refusals)   422 (also ``JobCPULimit``)
``LookupError`` (not stored)           404
``Overloaded`` / ``WorkerLost``        503 with ``Retry-After`` (also ``PreviewsBusy``, ``RenderWorkerLost``,
                                      ``ShareExceeded``: a client past its share of the fitting pool)
``FitTimeout``                         504 with ``Retry-After`` (also ``PreviewTimeout``)
``RendererUnavailable``                503 (no GL context on this machine)
``StoreFull``                          507
``TooManySaves``                       429 with ``Retry-After`` (saves per client per minute)
OSError ENOSPC/EDQUOT under a body     507 with ``Retry-After`` (the temporary directory is full)
``StoreUnavailable``                   503 with ``Retry-After``
``StoreConflict``                      409 (another save came first; ``NameTaken``: the name is another's)
``RecordDamaged``                      500 (only that record)
anything else                          500, logged with its traceback
=====================================  ======================================

A ``KeyError``/``IndexError`` or a pydantic ``ValidationError`` raised by
the service's own code is a bug, not bad input: 500, never 404 or 422.
"""

from __future__ import annotations

import errno
import logging
from typing import Any

import pydantic
from fastapi import FastAPI, Request, status
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from ..runtime import FitTimeout, Overloaded, RendererUnavailable, ShareExceeded, TooManySaves, WorkerLost
from ..store import StoreError

__all__ = ["install_error_handlers", "error_response"]

log = logging.getLogger("service.errors")


def error_response(
    status_code: int, detail: str, errors: list | None = None, headers: dict[str, str] | None = None
) -> JSONResponse:
    return JSONResponse({"detail": detail, "errors": errors or []}, status_code=status_code, headers=headers)


def _location(loc: tuple[Any, ...]) -> str:
    """('body', 'nk', 'n', 3) -> 'nk.n[3]' (in body)."""
    where = loc[0] if loc and loc[0] in ("body", "query", "path", "header", "cookie") else None
    parts = loc[1:] if where else loc
    text = ""
    for part in parts:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return f"`{text}` ({where})" if text and where else (f"`{text}`" if text else str(where or "request"))


def _short(value: Any) -> str | None:
    if isinstance(value, (int, float, bool)) or value is None:
        return repr(value)
    if isinstance(value, str) and len(value) <= 40:
        return repr(value)
    return None


async def _validation_error(request: Request, error: RequestValidationError) -> JSONResponse:
    items, lines = [], []
    for item in error.errors():
        loc = [p if isinstance(p, (str, int)) else str(p) for p in item.get("loc", ())]
        msg = item.get("msg", "invalid")
        if msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        if item.get("type") == "json_invalid":
            reason = (item.get("ctx") or {}).get("error", "")
            position = loc[-1] if loc and isinstance(loc[-1], int) else "?"
            line = f"the body must be valid JSON: {reason or msg} at character {position}"
        else:
            shown = _short(item.get("input")) if item.get("type") != "missing" else None
            line = f"{_location(tuple(loc))}: {msg}" + (f", got {shown}" if shown else "")
        lines.append(line)
        items.append({"loc": loc, "msg": msg[:500], "type": item.get("type", "value_error")})
    detail = "; ".join(lines[:5]) + (f"; and {len(lines) - 5} more" if len(lines) > 5 else "")
    return error_response(status.HTTP_422_UNPROCESSABLE_CONTENT, detail or "the request is invalid", items[:50])


# FastAPI's answer when a body cannot be decoded at all (JSON that is not
# UTF-8, a broken multipart stream); answered as any other invalid body.
_UNPARSABLE_BODY = "There was an error parsing the body"


_NO_SPACE = (errno.ENOSPC, errno.EDQUOT)


async def _http_error(request: Request, error: StarletteHTTPException) -> JSONResponse:
    cause = error.__cause__
    if isinstance(cause, OSError) and cause.errno in _NO_SPACE:
        # The body was spooled to a full temporary directory: the server's fault, not the file's.
        log.error("a request body could not be spooled: %s", cause)
        return error_response(
            status.HTTP_507_INSUFFICIENT_STORAGE,
            (
                "the server's temporary directory is full: the upload could not be received; nothing was "
                "fitted; retry later"
            ),
            headers={"Retry-After": "60"},
        )
    if error.status_code == status.HTTP_400_BAD_REQUEST and error.detail != _UNPARSABLE_BODY:
        # Starlette's multipart parser (a missing boundary, too many fields
        # or files): the body is invalid, as every other unparsable body.
        return error_response(
            status.HTTP_422_UNPROCESSABLE_CONTENT,
            f"the multipart body is invalid: {str(error.detail)[:200]}",
            [{"loc": ["body"], "msg": str(error.detail)[:200], "type": "body_unparsable"}],
        )
    if error.status_code == status.HTTP_400_BAD_REQUEST and error.detail == _UNPARSABLE_BODY:
        media_type = request.headers.get("content-type", "none").split(";")[0][:100]
        return error_response(
            status.HTTP_422_UNPROCESSABLE_CONTENT,
            f"the body could not be parsed as {media_type}: JSON must be UTF-8 text "
            "nested at most a few hundred levels deep, uploads multipart/form-data "
            "with a `file` part",
            [{"loc": ["body"], "msg": "unparsable body", "type": "body_unparsable"}],
        )
    return error_response(error.status_code, str(error.detail), headers=getattr(error, "headers", None))


async def _value_error(request: Request, error: ValueError) -> JSONResponse:
    return error_response(status.HTTP_422_UNPROCESSABLE_CONTENT, str(error)[:2000])


async def _lookup_error(request: Request, error: LookupError) -> JSONResponse:
    return error_response(status.HTTP_404_NOT_FOUND, str(error.args[0] if error.args else error)[:2000])


async def _busy(request: Request, error: Overloaded | WorkerLost | ShareExceeded) -> JSONResponse:
    return error_response(
        status.HTTP_503_SERVICE_UNAVAILABLE, str(error), headers={"Retry-After": str(error.retry_after)}
    )


async def _too_many(request: Request, error: TooManySaves) -> JSONResponse:
    return error_response(
        status.HTTP_429_TOO_MANY_REQUESTS, str(error), headers={"Retry-After": str(error.retry_after)}
    )


async def _timeout(request: Request, error: FitTimeout) -> JSONResponse:
    return error_response(status.HTTP_504_GATEWAY_TIMEOUT, str(error), headers={"Retry-After": str(error.retry_after)})


async def _no_renderer(request: Request, error: RendererUnavailable) -> JSONResponse:
    return error_response(status.HTTP_503_SERVICE_UNAVAILABLE, str(error))


async def _store_error(request: Request, error: StoreError) -> JSONResponse:
    if error.status == status.HTTP_409_CONFLICT:
        errors = [
            {
                "loc": ["body", getattr(error, "field", "expected_version")],
                "msg": str(error)[:500],
                "type": getattr(error, "type", "version_conflict"),
            }
        ]
        return error_response(error.status, str(error), errors)
    log.error("store: %s", error)
    headers = {"Retry-After": str(error.retry_after)} if error.status in (503, 507) else None
    return error_response(error.status, str(error), headers=headers)


async def _internal(request: Request, error: Exception) -> JSONResponse:
    log.exception("internal error on %s %s", request.method, request.url.path, exc_info=error)
    return error_response(
        status.HTTP_500_INTERNAL_SERVER_ERROR, f"internal error ({type(error).__name__}); it was logged"
    )


def install_error_handlers(app: FastAPI) -> None:
    """Register every handler of the table above on ``app``."""
    app.add_exception_handler(RequestValidationError, _validation_error)
    app.add_exception_handler(StarletteHTTPException, _http_error)
    app.add_exception_handler(pydantic.ValidationError, _internal)
    app.add_exception_handler(KeyError, _internal)
    app.add_exception_handler(IndexError, _internal)
    app.add_exception_handler(ValueError, _value_error)
    app.add_exception_handler(LookupError, _lookup_error)
    app.add_exception_handler(Overloaded, _busy)
    app.add_exception_handler(ShareExceeded, _busy)
    app.add_exception_handler(TooManySaves, _too_many)
    app.add_exception_handler(WorkerLost, _busy)
    app.add_exception_handler(FitTimeout, _timeout)
    app.add_exception_handler(RendererUnavailable, _no_renderer)
    app.add_exception_handler(StoreError, _store_error)
    app.add_exception_handler(Exception, _internal)
