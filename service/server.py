"""
The HTTP server
===============

:func:`serve` runs the app under uvicorn with bounds a slow or flooding
client cannot get past:

-   a header deadline (:class:`DeadlineH11Protocol`): a request's header
    must be complete within ``header_timeout_s`` of its first byte (and a
    new connection must send one within that time), else the connection is
    closed; uvicorn has no such timeout of its own;
-   the body deadline and size limits of
    :class:`service.api.middleware.RequestLimits` (408, 413);
-   ``limit_concurrency`` (``max_connections``: past it, 503) and the
    keep-alive timeout (``keep_alive_s``); header size stays bounded by
    h11 (16 KiB);
-   :class:`OncePerInterval`: repeated warnings of a flood (slow clients
    closed, the concurrency limit, invalid requests) are logged once, then
    counted once a minute, so a flood cannot grow the log.
"""

from __future__ import annotations

import asyncio
import logging
import threading
import time

import h11
import uvicorn
from uvicorn.protocols.http.h11_impl import H11Protocol

from .config import Settings

__all__ = ["DeadlineH11Protocol", "OncePerInterval", "protocol_with_deadline", "serve"]

log = logging.getLogger("uvicorn.error")
SLOW_CLIENT = "closed a connection whose request header did not arrive within %g s (COATED_HEADER_TIMEOUT_S)"


class OncePerInterval(logging.Filter):
    """
    Let the first record of each repeated message through, drop the rest
    for ``interval_s``, then let one through with the count of those dropped.
    """

    MESSAGES = ("Exceeded concurrency limit.", "Invalid HTTP request received.", SLOW_CLIENT)

    def __init__(self, interval_s: float = 60.0) -> None:
        super().__init__()
        self.interval_s = interval_s
        self._lock = threading.Lock()
        self._state: dict[str, tuple[float, int]] = {}

    def filter(self, record: logging.LogRecord) -> bool:
        if record.msg not in self.MESSAGES:
            return True
        now = time.monotonic()
        with self._lock:
            last, dropped = self._state.get(record.msg, (-1e18, 0))
            if now - last < self.interval_s:
                self._state[record.msg] = (last, dropped + 1)
                return False
            self._state[record.msg] = (now, 0)
        if dropped:
            record.msg = f"{record.msg} ({dropped} more like it in the last {self.interval_s:g} s)"
        return True


class DeadlineH11Protocol(H11Protocol):
    """uvicorn's h11 protocol with a deadline on each request's header."""

    header_timeout_s = 10.0

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        self._header_deadline: asyncio.TimerHandle | None = None
        super().connection_made(transport)
        self._arm_header_deadline()

    def _arm_header_deadline(self) -> None:
        if self._header_deadline is None:
            self._header_deadline = self.loop.call_later(self.header_timeout_s, self._header_timed_out)

    def _disarm_header_deadline(self) -> None:
        if self._header_deadline is not None:
            self._header_deadline.cancel()
            self._header_deadline = None

    def _header_timed_out(self) -> None:
        self._header_deadline = None
        if self.conn.their_state is h11.IDLE and not self.transport.is_closing():
            log.warning(SLOW_CLIENT, self.header_timeout_s)
            self.transport.close()

    def data_received(self, data: bytes) -> None:
        if self.conn.their_state is h11.IDLE:
            self._arm_header_deadline()
        super().data_received(data)
        if self.conn.their_state is not h11.IDLE:
            self._disarm_header_deadline()

    def on_response_complete(self) -> None:
        super().on_response_complete()
        if self.conn.their_state is h11.IDLE and self.conn.trailing_data[0]:
            self._arm_header_deadline()  # a pipelined request has begun

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm_header_deadline()
        super().connection_lost(exc)


def protocol_with_deadline(header_timeout_s: float) -> type[DeadlineH11Protocol]:
    """A :class:`DeadlineH11Protocol` subclass with its deadline set."""
    return type("DeadlineH11Protocol", (DeadlineH11Protocol,), {"header_timeout_s": header_timeout_s})


def serve(app, settings: Settings, host: str, port: int) -> None:
    """Run ``app`` on ``host``:``port`` until stopped (SIGINT/SIGTERM)."""
    config = uvicorn.Config(
        app, host=host, port=port, log_level="info",
        http=protocol_with_deadline(settings.header_timeout_s),
        limit_concurrency=settings.max_connections,
        timeout_keep_alive=settings.keep_alive_s,
        ws="none", lifespan="on",
    )
    flood = OncePerInterval()  # after Config, which configures uvicorn's logging
    logging.getLogger("uvicorn.error").addFilter(flood)
    server = uvicorn.Server(config)
    server.run()
