"""
Application
===========

:func:`create_app` builds the FastAPI application: settings, the store and
the fitting pool (made in the lifespan, the pool and this process warmed), the routers, and
the edge: the ``Host`` allow-list, the body size and time limits, CORS
(closed unless origins are configured) and the error answers
(:mod:`service.api.errors`: every 4xx and 5xx is ``{"detail": ...,
"errors": [...]}`` naming the field and the broken rule).

The server around it (header deadline, connection bound, flood logging)
is :mod:`service.runtime.server`.
"""

from __future__ import annotations

import asyncio
import logging
import time
from contextlib import asynccontextmanager
from pathlib import Path

from fastapi import FastAPI
from fastapi.middleware.cors import CORSMiddleware
from fastapi.staticfiles import StaticFiles

from fitting.cli.plugins import load_plugins

from .api.errors import install_error_handlers
from .api.middleware import ClaimWork, FrameDenial, HostAllowList, RequestLimits
from .api.routes import (
    colours,
    curves,
    environments,
    fit_downloads,
    fit_uploads,
    fits,
    health,
    ibl,
    imports,
    library,
    material_edits,
    materials,
    packs,
    preview,
    reference_texture,
    scenes,
    versions,
)
from .config import Settings
from .runtime import FitRunner, PreviewRunner, SaveRate, freeze_heap, thaw_heap, warm_process
from .derived import DerivedCache
from .jobs.evaluation import Evaluations
from .schemas import API_PREFIX
from .store import StoreError, open_store

log = logging.getLogger("service.store")

STATIC_DIR = Path(__file__).resolve().parents[1] / "static"
"""The browser editor, served at ``/``."""
GLSL_DIR = Path(__file__).resolve().parents[1] / "preview_shaders" / "glsl"
"""The project's GLSL, served at ``/glsl/`` for the editor's WebGL2 preview."""
THREE_DIR = Path(__file__).resolve().parents[1] / "scripts" / "three" / "node_modules" / "three"
"""three.js as pinned in scripts/three/package-lock.json (``scripts/bootstrap``
installs it): its ``build/`` and ``examples/jsm/`` served at ``/vendor/three/``
for the three.js material and its example page."""
THREE_PACKAGE_DIR = Path(__file__).resolve().parents[1] / "web" / "three" / "src"
"""The three.js material's package (web/three/, npm ``coated-conductor-three``),
its modules served at ``/static/three/`` for the example page."""
BABYLON_DIR = Path(__file__).resolve().parents[1] / "scripts" / "babylon" / "node_modules" / "@babylonjs"
"""Babylon.js (``@babylonjs/core`` and ``@babylonjs/loaders``) as pinned in
scripts/babylon/package-lock.json (``scripts/bootstrap`` installs them),
served at ``/vendor/babylon/core/`` and ``/vendor/babylon/loaders/``."""
BABYLON_PACKAGE_DIR = Path(__file__).resolve().parents[1] / "web" / "babylon" / "src"
"""The Babylon.js package (web/babylon/, npm ``coated-conductor-babylon``),
its modules served at ``/static/babylon/``."""
SWAGGER_UI_DIR = Path(__file__).resolve().parents[1] / "scripts" / "swagger-ui" / "node_modules" / "swagger-ui-dist"
"""Swagger UI as pinned in scripts/swagger-ui/package-lock.json (``scripts/bootstrap``
installs it), served at ``/vendor/swagger-ui/`` for ``/docs``."""

__all__ = ["create_app"]


def _offline_docs(app: FastAPI) -> None:
    """
    ``/docs``: Swagger UI 5 (reads OpenAPI 3.1) from npm ``swagger-ui-dist``
    as pinned in scripts/swagger-ui/package-lock.json, its assets at
    ``/vendor/swagger-ui/``: nothing is fetched from another host (no CDN,
    no validator badge, a local favicon). Without ``scripts/bootstrap``'s
    install the service still starts and ``/docs`` answers 503 saying so.
    """
    from fastapi.openapi.docs import get_swagger_ui_html
    from fastapi.responses import PlainTextResponse

    app.mount("/vendor/swagger-ui", StaticFiles(directory=SWAGGER_UI_DIR, check_dir=False), name="swagger-ui")

    @app.get("/docs", include_in_schema=False)
    async def docs():
        if not (SWAGGER_UI_DIR / "swagger-ui-bundle.js").is_file():
            return PlainTextResponse(
                f"the API docs need Swagger UI at {SWAGGER_UI_DIR}: run scripts/bootstrap "
                "(npm ci in scripts/swagger-ui); the API itself is described at /openapi.json",
                status_code=503,
            )
        return get_swagger_ui_html(
            openapi_url=app.openapi_url,
            title=f"{app.title} - API docs",
            swagger_js_url="/vendor/swagger-ui/swagger-ui-bundle.js",
            swagger_css_url="/vendor/swagger-ui/swagger-ui.css",
            swagger_favicon_url="/vendor/swagger-ui/favicon-32x32.png",
            # validatorUrl None: no badge asking validator.swagger.io about the document.
            swagger_ui_parameters={"validatorUrl": None, "defaultModelsExpandDepth": 1},
        )


async def _sweep_drafts(store, settings: Settings) -> None:
    """Every ``draft_sweep_s``: drafts past their time to live, then past the quota, removed."""
    while True:
        try:
            removed = await asyncio.to_thread(
                store.expire_drafts, time.time() - settings.draft_ttl_s, settings.draft_max_bytes
            )
            if removed:
                log.info("removed %d drafts (COATED_DRAFT_TTL_S, COATED_DRAFT_MAX_BYTES)", removed)
        except StoreError as error:
            log.warning("draft sweep: %s", error)
        await asyncio.sleep(settings.draft_sweep_s)


def create_app(settings: Settings | None = None) -> FastAPI:
    """
    The service application.

    ``settings`` default to :class:`service.config.Settings` from the
    environment (``COATED_*``). The lifespan opens the store
    (:func:`service.store.open_store`: PostgreSQL at ``COATED_STORE_URL``, else
    SQLite under ``settings.data_dir``; schema migrated), the fitting pool (warmed at start-up when
    ``settings.warm_pool``) and the render pool (:class:`service.runtime.previews.PreviewRunner`, started
    by the first preview), and closes them at shutdown.
    """
    settings = settings or Settings()
    load_plugins(settings.plugins)  # as python -m service does before its fork server; imported once

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        store = await asyncio.to_thread(open_store, settings)
        await asyncio.to_thread(store.check)
        runner = FitRunner(
            settings.fit_workers,
            settings.max_in_flight,
            settings.fit_timeout_s,
            settings.job_cpu_limit_s,
            express_workers=settings.fit_express_workers,
            client_bulk_jobs=settings.client_bulk_jobs,
        )
        # Its processes start on the first preview: a service that draws none starts none.
        previews = PreviewRunner(settings.max_previews_in_flight, settings.preview_timeout_s, settings.job_cpu_limit_s)
        app.state.store, app.state.runner, app.state.previews = store, runner, previews
        # New fits' metrics, evaluated when the pool is idle (or when asked for).
        app.state.evaluations = Evaluations(store, runner, settings.metrics_idle_s or None)
        app.state.derived = DerivedCache(settings.derived_cache_bytes)
        app.state.save_rate = SaveRate(settings.saves_per_client_per_minute)
        sweeper = asyncio.create_task(_sweep_drafts(store, settings))
        try:
            if settings.warm_pool:
                # The workers and this process (curves, reference textures) at once.
                await asyncio.gather(runner.warm_up(), asyncio.to_thread(warm_process))
            if settings.freeze_heap:
                # What start-up made (imports, caches) out of the collector's full passes.
                freeze_heap()
            yield
        finally:
            sweeper.cancel()
            app.state.evaluations.close()
            previews.close()
            runner.close()
            store.close()
            if settings.freeze_heap:
                thaw_heap()

    app = FastAPI(
        title="Coated-metal Fresnel service",
        version="1.0.0",
        summary="Fit the coated-conductor Fresnel model (Vernooij 2024) to measured n, k "
        "and download float16 coefficient packs.",
        lifespan=lifespan,
        docs_url=None,  # served below from local Swagger UI assets (works offline)
        redoc_url=None,  # ReDoc's page loads its script and fonts from CDNs: /docs covers it
    )
    app.state.settings = settings
    install_error_handlers(app)
    for module in (
        health,
        materials,
        material_edits,
        versions,
        library,
        imports,
        fits,
        fit_uploads,
        fit_downloads,
        packs,
        preview,
        reference_texture,
        environments,
        curves,
        colours,
        scenes,
        ibl,
    ):
        app.include_router(module.router)
    _offline_docs(app)
    app.mount("/glsl", StaticFiles(directory=GLSL_DIR), name="glsl")
    # check_dir=False: without scripts/bootstrap's three the service still
    # starts, and only the three.js example's files answer 404.
    for part in ("build", "examples/jsm"):
        app.mount(
            f"/vendor/three/{part}", StaticFiles(directory=THREE_DIR / part, check_dir=False), name=f"three-{part}"
        )
    for part in ("core", "loaders"):
        app.mount(
            f"/vendor/babylon/{part}",
            StaticFiles(directory=BABYLON_DIR / part, check_dir=False),
            name=f"babylon-{part}",
        )
    # The three.js and Babylon.js packages (web/*/src/) at /static/three/ and
    # /static/babylon/, before /static, whose directory has neither.
    app.mount("/static/three", StaticFiles(directory=THREE_PACKAGE_DIR), name="three-package")
    app.mount("/static/babylon", StaticFiles(directory=BABYLON_PACKAGE_DIR), name="babylon-package")
    # /static/...: the page's modules at a path of their own for other pages.
    app.mount("/static", StaticFiles(directory=STATIC_DIR), name="static")
    # The browser editor (static/), after the API so that /api, /docs and
    # /openapi.json keep their routes; html=True serves index.html at /.
    app.mount("/", StaticFiles(directory=STATIC_DIR, html=True), name="editor")
    if settings.cors_origins:
        app.add_middleware(
            CORSMiddleware,
            allow_origins=settings.cors_origins,
            allow_methods=["GET", "POST", "PATCH", "DELETE"],
            allow_headers=["Authorization", "Content-Type"],
        )
    token = settings.api_token.get_secret_value() if settings.api_token else None
    app.add_middleware(
        ClaimWork,
        token=token,
        scene_path=f"{API_PREFIX}/scenes",
        pack_path=f"{API_PREFIX}/packs",
        save_paths=tuple(f"{API_PREFIX}/fits{p}" for p in ("", "/upload", "/from-curves")),
    )
    app.add_middleware(
        RequestLimits,
        max_body_bytes=settings.max_body_bytes,
        max_upload_bytes=settings.max_upload_bytes,
        upload_paths=(f"{API_PREFIX}/fits/upload", f"{API_PREFIX}/fits/import"),
        body_timeout_s=settings.body_timeout_s,
    )
    # Outermost: a request for another host name is refused before anything else,
    # and every answer (refusals too) forbids framing.
    app.add_middleware(HostAllowList, allowed=tuple(settings.allowed_hosts))
    app.add_middleware(FrameDenial)
    return app
