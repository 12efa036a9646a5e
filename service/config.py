"""
Settings
========

Every setting of the service in one :class:`Settings` class, read from
environment variables with the prefix ``COATED_`` (``COATED_DATA_DIR``,
``COATED_FIT_TIMEOUT_S``, ...) or passed to :func:`service.main.create_app`.

-   :class:`Settings`: the settings, with their defaults and limits.
-   :func:`is_loopback`: whether a bind address only reaches this machine.
"""

from __future__ import annotations

import ipaddress
import os
from pathlib import Path

from pydantic import Field, SecretStr, model_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

__all__ = ["Settings", "is_loopback"]


def is_loopback(host: str) -> bool:
    """True for ``localhost`` and loopback IP addresses (127.0.0.0/8, ::1)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class Settings(BaseSettings):
    """
    Settings of the HTTP service (environment prefix ``COATED_``).

    Attributes
    ----------
    data_dir
        Directory of the SQLite store (``store.sqlite3``), created if missing
        (not used when ``store_url`` names a PostgreSQL server).
    store_url
        ``postgresql://user:password@host:port/db``: the PostgreSQL store
        shared by every replica (unset: SQLite under ``data_dir``).
    store_pool_min, store_pool_max
        Connections to PostgreSQL this process keeps open at least and
        opens at most (the pool); N replicas open at most N x
        ``store_pool_max``, which must stay below the role's CONNECTION
        LIMIT (docs/deploy.md).
    store_pool_timeout_s
        Longest wait for a pooled connection (then 503 + Retry-After).
    store_statement_timeout_s
        Longest statement on the PostgreSQL server (``statement_timeout``).
    store_migrate
        Bring the store's schema to this code's version at start-up (false:
        refuse to start on an older schema; ``python -m service migrate``).
    host
        The address the server binds to; decides whether write endpoints
        need a token by default (see ``require_token``).
    api_token
        Bearer token of the write endpoints.
    require_token
        Whether write endpoints need ``Authorization: Bearer <api_token>``;
        unset means: required when ``host`` is not a loopback address. A
        required token that is not set refuses to start.
    cors_origins
        Origins allowed by CORS; empty (the default) sends no CORS headers,
        so browsers refuse cross-origin calls.
    fit_workers
        Worker processes of the fitting pool (default: the CPU count).
    fit_express_workers
        Worker processes more, for cheap parts only (a library or upload
        fit's parts, a live refit step): they start at once while every
        other worker runs an expensive part (a full curve refit, a scene's
        material), instead of waiting for one to end (default 1; 0 turns
        the express lane off).
    fit_queue
        Fits that may wait for a worker; past ``fit_workers + fit_queue``
        fits in flight a new fit is answered 503 with ``Retry-After``.
    fit_timeout_s
        Time limit of one fit, seconds, waiting included; past it the
        request is answered 504 and its job cancelled.
    job_cpu_limit_s
        CPU time one part of a job may use in its worker, seconds; past it
        the job stops and is answered 422.
    warm_pool
        Start the worker processes at start-up (so the first fit is fast).
    freeze_heap
        After start-up, collect once and freeze what the server process
        holds out of the garbage collector's full passes
        (:func:`service.runtime.worker.freeze_heap`; thawed at shutdown). Off for an
        app embedded in a process that is not its own (a test runner's
        in-process clients), whose heap is the host's: each start would
        collect all of it.
    metrics_samples
        Side of the scoring grid of the fit metrics (the paper: 100).
    metrics_idle_s
        A new fit's metrics are evaluated in the background once the pool
        has had no job for this many seconds (:mod:`service.jobs.evaluation`);
        0 evaluates them only when asked for.
    derived_cache_bytes
        Bytes of what is derived from stored fits kept in memory (exports per
        fit, format, eta_i and roughnesses; previews per fit and view), each
        made once; the least recently used dropped past it.
    max_body_bytes, max_upload_bytes
        Largest JSON body and largest upload (multipart body), bytes; larger
        requests get 413.
    max_preview_size
        Largest preview side in pixels.
    max_previews_in_flight
        Previews rendered at once (a spectral-reference preview is seconds of
        CPU), and the processes of the render pool that draw them
        (:class:`service.runtime.previews.PreviewRunner`); past it a preview
        request is answered 503 with Retry-After.
    preview_timeout_s
        Time limit of one preview (or GL texture) request, seconds, waiting
        included; past it the request is answered 504 and its render
        cancelled. Each render also has ``job_cpu_limit_s``.
    allowed_hosts
        ``Host`` names the service answers (DNS-rebinding guard); default the
        loopback names and addresses. ``.example.com`` allows a domain and
        its subdomains, ``*`` any (only behind a proxy that checks it).
    header_timeout_s, body_timeout_s
        A request's header must arrive within ``header_timeout_s`` of its
        first byte (else the connection is closed), its body within
        ``body_timeout_s`` (else 408).
    min_body_rate
        Bytes per second a request body must arrive at, from 2 s after its
        header (it must have sent ``min_body_rate x (elapsed - 2 s)``
        bytes at any time): a body behind it is answered 408 and its
        connection closed, and meanwhile counts as idle (a new connection
        past a bound may close it).
    keep_alive_s
        An idle keep-alive connection is closed after this many seconds.
    client_bulk_jobs
        Reads computed on demand (exports), packs and scenes of one client
        (its address, or the token's holder) in the fitting pool at once;
        past it 503 with ``Retry-After``. Unset: ``fit_workers``. Together
        these bulk jobs hold at most ``fit_queue`` of the pool's slots (at
        least one): ``fit_workers`` are kept for saves.
    saves_per_client_per_minute
        Saves (``POST /fits``, ``/fits/upload``, a non-draft
        ``/fits/from-curves``) of one client (address, or the token's
        holder) in any minute, per replica; past it 429 with
        ``Retry-After``.
    drain_timeout_s
        After SIGTERM (or SIGINT), requests in flight may finish for this
        long; then they are cancelled (their jobs too) and the process
        exits. Shorter than common supervisors' grace (Kubernetes' and
        systemd's 30 s, Docker's 10 s: set it below that one).
    max_connections
        Connections at once. A new connection past it closes the longest
        idle one (no request in progress); with none idle it is admitted
        only for ``/healthz`` (16 more are kept for it), else answered 503.
    max_connections_per_client
        Connections at once from one client address, by the same rule.
    store_max_bytes
        Quota of the store file (unset: none); a save past it is answered 507.
    store_min_free_bytes
        Free disk space below which the store counts as full: fits are
        refused 507 before any CPU is spent, ``/healthz`` says so.
    draft_ttl_s
        Drafts (the editor's refits while editing, never saved) are removed
        this long after they were made (default a day), in the background.
    draft_max_bytes
        The drafts' quota: past it the oldest drafts are removed first.
    draft_sweep_s
        How often drafts are swept (past their time to live, then the quota).
    materials_page_max
        Most saved materials in one page of ``GET /api/v1/materials``.
    plugins
        Modules to import at the start, separated by commas: each registers
        an export format or a model kind (:mod:`fitting.cli.plugins`).
    """

    model_config = SettingsConfigDict(env_prefix="COATED_", extra="ignore")

    data_dir: Path = Path("data")
    host: str = "127.0.0.1"
    api_token: SecretStr | None = None
    require_token: bool | None = None
    cors_origins: list[str] = Field(default_factory=list)
    fit_workers: int = Field(default_factory=lambda: os.cpu_count() or 1, ge=1, le=256)
    fit_express_workers: int = Field(default=1, ge=0, le=16)
    fit_queue: int = Field(default=8, ge=0, le=10_000)
    fit_timeout_s: float = Field(default=120.0, gt=0.0, le=3600.0)
    job_cpu_limit_s: float = Field(default=60.0, gt=0.0, le=3600.0)
    warm_pool: bool = True
    freeze_heap: bool = True
    metrics_samples: int = Field(default=100, ge=10, le=400)
    metrics_idle_s: float = Field(default=1.0, ge=0.0, le=3600.0)
    derived_cache_bytes: int = Field(default=64_000_000, ge=0, le=8_000_000_000)
    max_body_bytes: int = Field(default=1_000_000, ge=1_000)
    max_upload_bytes: int = Field(default=2_000_000, ge=1_000)
    max_preview_size: int = Field(default=1024, ge=64, le=2048)
    max_previews_in_flight: int = Field(default=2, ge=1, le=64)
    preview_timeout_s: float = Field(default=60.0, gt=0.0, le=3600.0)
    allowed_hosts: list[str] = Field(default_factory=lambda: ["localhost", "127.0.0.1", "::1"])
    header_timeout_s: float = Field(default=10.0, gt=0.0, le=600.0)
    body_timeout_s: float = Field(default=30.0, gt=0.0, le=3600.0)
    min_body_rate: float = Field(default=1024.0, gt=0.0, le=1e9)
    keep_alive_s: float = Field(default=5.0, gt=0.0, le=600.0)
    drain_timeout_s: float = Field(default=25.0, ge=0.0, le=3600.0)
    client_bulk_jobs: int | None = Field(default=None, ge=1, le=10_000)
    saves_per_client_per_minute: int = Field(default=600, ge=1, le=1_000_000)
    max_connections: int = Field(default=512, ge=8, le=100_000)
    max_connections_per_client: int = Field(default=128, ge=1, le=100_000)
    store_max_bytes: int | None = Field(default=None, ge=100_000)
    store_min_free_bytes: int = Field(default=16_000_000, ge=0)
    draft_ttl_s: float = Field(default=86_400.0, gt=0.0)
    draft_max_bytes: int = Field(default=64_000_000, ge=0)
    draft_sweep_s: float = Field(default=60.0, gt=0.0, le=86_400.0)
    materials_page_max: int = Field(default=500, ge=1, le=10_000)
    store_url: SecretStr | None = None
    store_pool_min: int = Field(default=1, ge=0, le=100)
    store_pool_max: int = Field(default=4, ge=1, le=100)
    store_pool_timeout_s: float = Field(default=5.0, gt=0.0, le=600.0)
    store_statement_timeout_s: float = Field(default=30.0, gt=0.0, le=3600.0)
    store_migrate: bool = True
    plugins: str = ""

    @model_validator(mode="after")
    def _check_token(self) -> "Settings":
        if self.token_required and not (self.api_token and self.api_token.get_secret_value()):
            raise ValueError(
                f"`api_token` (COATED_API_TOKEN) must be set: write endpoints need a "
                f"bearer token when the service binds to the non-loopback address "
                f"{self.host!r} (or set COATED_REQUIRE_TOKEN=false explicitly)"
            )
        return self

    @model_validator(mode="after")
    def _check_store(self) -> "Settings":
        url = self.store_url.get_secret_value() if self.store_url else ""
        if self.store_url is not None and not url.startswith(("postgresql://", "postgres://")):
            raise ValueError(
                "`store_url` (COATED_STORE_URL) must be a postgresql:// URL, or unset "
                "for the SQLite store under the data directory"
            )
        if self.store_pool_min > self.store_pool_max:
            raise ValueError(
                f"`store_pool_min` ({self.store_pool_min}) must not exceed `store_pool_max` ({self.store_pool_max})"
            )
        return self

    @property
    def token_required(self) -> bool:
        """Whether write endpoints check the bearer token."""
        if self.require_token is None:
            return not is_loopback(self.host)
        return self.require_token

    @property
    def store_path(self) -> Path:
        """The SQLite file of the store."""
        return self.data_dir / "store.sqlite3"

    @property
    def max_in_flight(self) -> int:
        """Fits running or waiting, at most."""
        return self.fit_workers + self.fit_queue
