"""
Application
===========

:func:`create_app` builds the FastAPI application: settings, the store and
the fitting pool (made in the lifespan), the routers, the body-size limit,
CORS (closed unless origins are configured) and the error answers (every
4xx and 5xx is ``{"detail": ..., "errors": [...]}`` naming the field and the
broken rule).
"""

from __future__ import annotations

import json
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Any

from fastapi import FastAPI, Request, status
from fastapi.exceptions import RequestValidationError
from fastapi.middleware.cors import CORSMiddleware
from fastapi.responses import JSONResponse
from fastapi.staticfiles import StaticFiles
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from .api.routes import curves, fits, health, materials, packs, preview, reference_texture, scenes
from .config import Settings
from .fitting_jobs import FitRunner
from .models import API_PREFIX
from .store import SQLiteStore

STATIC_DIR = Path(__file__).resolve().parents[1] / "static"
"""The browser editor, served at ``/``."""
GLSL_DIR = Path(__file__).resolve().parents[1] / "preview_shaders" / "glsl"
"""The project's GLSL, served at ``/glsl/`` for the editor's WebGL2 preview."""

__all__ = ["create_app", "BodySizeLimit"]


class BodySizeLimit:
    """
    ASGI middleware: a request body larger than the limit is answered 413
    before the application sees it (``max_upload_bytes`` for the upload
    route, ``max_body_bytes`` elsewhere). Checks Content-Length up front and
    counts the bytes of streamed bodies.
    """

    def __init__(self, app: ASGIApp, max_body_bytes: int, max_upload_bytes: int,
                 upload_paths: tuple[str, ...]) -> None:
        self.app = app
        self.max_body_bytes = max_body_bytes
        self.max_upload_bytes = max_upload_bytes
        self.upload_paths = upload_paths

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        limit = self.max_upload_bytes if scope["path"] in self.upload_paths else self.max_body_bytes
        setting = "COATED_MAX_UPLOAD_BYTES" if scope["path"] in self.upload_paths else "COATED_MAX_BODY_BYTES"
        headers = dict(scope.get("headers") or [])
        declared = headers.get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > limit:
            await self._refuse(send, limit, setting)
            return
        chunks: list[bytes] = []
        size = 0
        while True:
            message = await receive()
            if message["type"] == "http.disconnect":
                return
            chunk = message.get("body", b"")
            size += len(chunk)
            if size > limit:
                await self._refuse(send, limit, setting)
                return
            chunks.append(chunk)
            if not message.get("more_body", False):
                break
        body = b"".join(chunks)
        sent = False

        async def replay() -> Message:
            nonlocal sent
            if not sent:
                sent = True
                return {"type": "http.request", "body": body, "more_body": False}
            return await receive()

        await self.app(scope, replay, send)

    @staticmethod
    async def _refuse(send: Send, limit: int, setting: str) -> None:
        body = json.dumps({
            "detail": f"the request body must be at most {limit} bytes ({setting})",
            "errors": [],
        }).encode()
        await send({
            "type": "http.response.start", "status": status.HTTP_413_CONTENT_TOO_LARGE,
            "headers": [(b"content-type", b"application/json"),
                        (b"content-length", str(len(body)).encode()),
                        (b"connection", b"close")],
        })
        await send({"type": "http.response.body", "body": body})


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
            msg = msg[len("Value error, "):]
        if item.get("type") == "json_invalid":
            reason = (item.get("ctx") or {}).get("error", "")
            position = loc[-1] if loc and isinstance(loc[-1], int) else "?"
            line = f"the body must be valid JSON: {reason or msg} at character {position}"
        else:
            shown = _short(item.get("input")) if item.get("type") != "missing" else None
            line = f"{_location(tuple(loc))}: {msg}" + (f", got {shown}" if shown else "")
        lines.append(line)
        items.append({"loc": loc, "msg": msg, "type": item.get("type", "value_error")})
    detail = "; ".join(lines[:5]) + (f"; and {len(lines) - 5} more" if len(lines) > 5 else "")
    return JSONResponse(
        {"detail": detail or "the request is invalid", "errors": items[:50]},
        status_code=status.HTTP_422_UNPROCESSABLE_CONTENT,
    )


# FastAPI's answer when a body cannot be decoded at all (JSON that is not
# UTF-8, a broken multipart stream); answered as any other invalid body.
_UNPARSABLE_BODY = "There was an error parsing the body"


async def _http_error(request: Request, error: StarletteHTTPException) -> JSONResponse:
    if error.status_code == status.HTTP_400_BAD_REQUEST and error.detail == _UNPARSABLE_BODY:
        media_type = request.headers.get("content-type", "none").split(";")[0]
        return JSONResponse(
            {"detail": f"the body could not be parsed as {media_type}: JSON must be UTF-8 text "
                       "nested at most a few hundred levels deep, uploads multipart/form-data "
                       "with a `file` part",
             "errors": [{"loc": ["body"], "msg": "unparsable body", "type": "body_unparsable"}]},
            status_code=status.HTTP_422_UNPROCESSABLE_CONTENT,
        )
    return JSONResponse(
        {"detail": str(error.detail), "errors": []},
        status_code=error.status_code,
        headers=getattr(error, "headers", None),
    )


def _offline_docs(app: FastAPI) -> None:
    """``/docs``: Swagger UI from the ``swagger_ui_bundle`` package, not a CDN."""
    import swagger_ui_bundle
    from fastapi.openapi.docs import get_swagger_ui_html

    app.mount("/docs-assets", StaticFiles(directory=swagger_ui_bundle.swagger_ui_path), name="docs-assets")

    @app.get("/docs", include_in_schema=False)
    async def docs():
        return get_swagger_ui_html(
            openapi_url=app.openapi_url, title=f"{app.title} - API docs",
            swagger_js_url="/docs-assets/swagger-ui-bundle.js",
            swagger_css_url="/docs-assets/swagger-ui.css",
            swagger_favicon_url="/docs-assets/favicon-32x32.png",
        )


def create_app(settings: Settings | None = None) -> FastAPI:
    """
    The service application.

    ``settings`` default to :class:`service.config.Settings` from the
    environment (``COATED_*``). The lifespan opens the SQLite store under
    ``settings.data_dir`` and the fitting pool (warmed at start-up when
    ``settings.warm_pool``), and closes both at shutdown.
    """
    settings = settings or Settings()

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        store = SQLiteStore(settings.store_path)
        store.check()
        runner = FitRunner(settings.fit_workers, settings.max_in_flight, settings.fit_timeout_s)
        app.state.store, app.state.runner = store, runner
        try:
            if settings.warm_pool:
                await runner.warm_up()
            yield
        finally:
            if app.state.preview_renderer is not None:
                app.state.preview_renderer.close()
                app.state.preview_renderer = None
            runner.close()
            store.close()

    app = FastAPI(
        title="Coated-metal Fresnel service",
        version="1.0.0",
        summary="Fit the coated-conductor Fresnel model (Vernooij 2024) to measured n, k "
                "and download float16 coefficient packs.",
        lifespan=lifespan,
        docs_url=None,  # served below from local Swagger UI assets (works offline)
    )
    app.state.settings = settings
    app.state.preview_renderer = None
    app.add_exception_handler(RequestValidationError, _validation_error)
    app.add_exception_handler(StarletteHTTPException, _http_error)
    for module in (health, materials, fits, packs, preview, reference_texture, curves, scenes):
        app.include_router(module.router)
    _offline_docs(app)
    app.mount("/glsl", StaticFiles(directory=GLSL_DIR), name="glsl")
    # The browser editor (static/), after the API so that /api, /docs and
    # /openapi.json keep their routes; html=True serves index.html at /.
    app.mount("/", StaticFiles(directory=STATIC_DIR, html=True), name="editor")
    if settings.cors_origins:
        app.add_middleware(
            CORSMiddleware, allow_origins=settings.cors_origins,
            allow_methods=["GET", "POST"], allow_headers=["Authorization", "Content-Type"],
        )
    app.add_middleware(
        BodySizeLimit, max_body_bytes=settings.max_body_bytes,
        max_upload_bytes=settings.max_upload_bytes, upload_paths=(f"{API_PREFIX}/fits/upload",),
    )
    return app
