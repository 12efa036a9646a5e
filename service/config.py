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
        Directory of the SQLite store (``store.sqlite3``), created if missing.
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
    fit_queue
        Fits that may wait for a worker; past ``fit_workers + fit_queue``
        fits in flight a new fit is answered 503 with ``Retry-After``.
    fit_timeout_s
        Time limit of one fit, seconds, waiting included; past it the
        request is answered 504.
    warm_pool
        Start the worker processes at start-up (so the first fit is fast).
    metrics_samples
        Side of the scoring grid of the fit metrics (the paper: 100).
    max_body_bytes, max_upload_bytes
        Largest JSON body and largest upload (multipart body), bytes; larger
        requests get 413.
    max_preview_size
        Largest preview side in pixels.
    max_previews_in_flight
        Previews rendered at once (a spectral-reference preview is seconds of
        CPU); past it a preview request is answered 503 with Retry-After.
    """

    model_config = SettingsConfigDict(env_prefix="COATED_", extra="ignore")

    data_dir: Path = Path("data")
    host: str = "127.0.0.1"
    api_token: SecretStr | None = None
    require_token: bool | None = None
    cors_origins: list[str] = Field(default_factory=list)
    fit_workers: int = Field(default_factory=lambda: os.cpu_count() or 1, ge=1, le=256)
    fit_queue: int = Field(default=8, ge=0, le=10_000)
    fit_timeout_s: float = Field(default=120.0, gt=0.0, le=3600.0)
    warm_pool: bool = True
    metrics_samples: int = Field(default=100, ge=10, le=400)
    max_body_bytes: int = Field(default=1_000_000, ge=1_000)
    max_upload_bytes: int = Field(default=2_000_000, ge=1_000)
    max_preview_size: int = Field(default=1024, ge=64, le=2048)
    max_previews_in_flight: int = Field(default=2, ge=1, le=64)

    @model_validator(mode="after")
    def _check_token(self) -> "Settings":
        if self.token_required and not (self.api_token and self.api_token.get_secret_value()):
            raise ValueError(
                f"`api_token` (COATED_API_TOKEN) must be set: write endpoints need a "
                f"bearer token when the service binds to the non-loopback address "
                f"{self.host!r} (or set COATED_REQUIRE_TOKEN=false explicitly)"
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
