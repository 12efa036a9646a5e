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
-   a minimum body rate (``min_body_rate`` bytes per second after the
    header, past :data:`service.runtime.admission.BODY_GRACE_S`): a body
    behind it is answered 408 and its connection closed, and, from its
    first moment, one behind the rate counts as idle for admission
    (:meth:`DeadlineH11Protocol.idle`), so a trickle holds no connection a
    new one needs, however often it reconnects;
-   a header size bound (:data:`MAX_HEADER_BYTES`, 16 KiB; past it 431
    and the connection closed): h11 bounds only a header still incomplete,
    so one that arrives whole in one read is counted here;
-   admission (:class:`service.runtime.admission.Admission`): at most
    ``max_connections`` connections, ``max_connections_per_client`` from one
    address; a connection past a bound closes the longest idle one (no
    request in progress, or a body behind the rate; for the per-address
    bound also nothing sent or received on it for :data:`IDLE_GRACE_S`: a
    flood of idle connections only churns itself, while a burst's
    connections whose requests are still on their way, and a keep-alive
    connection between two requests, are not cut), and with none idle it is
    admitted for ``/healthz`` alone, in a reserve of its own
    (:data:`HEALTH_RESERVE`, never closed for an ordinary connection; past
    it the address holding most of it loses a silent one), every other request on it answered 503 with
    ``Retry-After``, its request due within the grace, the connection
    closed after its answer; so ``/healthz`` is always answered and a burst
    past the bound gets 503s, not connection resets. uvicorn's own
    ``limit_concurrency`` is off: past it uvicorn answered 503 to
    ``/healthz`` too;
-   the keep-alive timeout (``keep_alive_s``);
-   :class:`service.runtime.flood_log.OncePerInterval`: repeated warnings
    of a flood (slow clients closed, the concurrency limit, invalid
    requests) are logged once, then counted once a minute, so a flood
    cannot grow the log.

This module is the one adapter to uvicorn's internals (its h11 protocol's
hooks and state, :data:`UVICORN_PRIVATE`); :func:`uvicorn_mismatches` says
what of them a uvicorn release no longer holds, and
``tests/service/test_runtime_private.py`` fails on any.

SIGTERM and SIGINT stop it gracefully (uvicorn's shutdown: connections
drained for at most ``drain_timeout_s``, then the requests still in flight
cancelled, the lifespan's pools, whose jobs are cancelled, and store
closed), and the process then exits
with the signal's conventional status (143, 130) through ``SystemExit``
(:func:`_exit_after_shutdown`), so that its exit handlers run.
"""

from __future__ import annotations

import ast
import asyncio
import inspect
import json
import logging
import signal
import threading

import h11
import uvicorn
from uvicorn.protocols.http.flow_control import FlowControl
from uvicorn.protocols.http.h11_impl import H11Protocol, RequestResponseCycle

from ..config import Settings
from .admission import BODY_GRACE_S, HEALTH_RESERVE, IDLE_GRACE_S, Admission
from .flood_log import OVER_BOUND, SLOW_BODY, SLOW_CLIENT, OncePerInterval

__all__ = [
    "DeadlineH11Protocol",
    "protocol_with_deadline",
    "serve",
    "MAX_HEADER_BYTES",
    "HEALTH_RESERVE",
    "IDLE_GRACE_S",
    "BODY_GRACE_S",
    "UVICORN_PRIVATE",
    "uvicorn_mismatches",
]

UVICORN_PRIVATE = {
    H11Protocol: (
        "connection_made",
        "data_received",
        "on_response_complete",
        "connection_lost",
        "conn",
        "cycle",
        "server_state",
        "transport",
        "client",
        "loop",
        "flow",
    ),
    RequestResponseCycle: ("response_complete", "response_started", "body"),
    FlowControl: ("read_paused",),
    uvicorn.Server: ("server_state",),
}
"""What :class:`DeadlineH11Protocol` uses of uvicorn's h11 protocol: methods it overrides, attributes it reads."""


def uvicorn_mismatches() -> list[str]:
    """What of :data:`UVICORN_PRIVATE` this uvicorn's classes neither define nor assign (empty when all is there)."""
    found = []
    for cls, names in UVICORN_PRIVATE.items():
        tree = ast.parse(inspect.getsource(cls))
        assigned = {
            node.attr
            for node in ast.walk(tree)
            if isinstance(node, ast.Attribute)
            and isinstance(node.ctx, ast.Store)
            and isinstance(node.value, ast.Name)
            and node.value.id == "self"
        }
        found += [
            f"uvicorn's {cls.__name__} has no {name} (uvicorn {uvicorn.__version__})"
            for name in names
            if not callable(getattr(cls, name, None)) and name not in assigned
        ]
    return found


log = logging.getLogger("uvicorn.error")
MAX_HEADER_BYTES = 16 * 1024
"""Largest request line and header fields together (h11's own bound for an incomplete one)."""
_HEALTH_REQUESTS = (b"GET /healthz", b"HEAD /healthz")
_HEADER_END = b"\r\n\r\n"
_TOO_LARGE = json.dumps(
    {
        "detail": f"the request header must be at most {MAX_HEADER_BYTES} bytes",
        "errors": [],
    }
).encode()
_FULL = json.dumps(
    {
        "detail": "the service has as many connections as it accepts, all busy "
        "(COATED_MAX_CONNECTIONS, COATED_MAX_CONNECTIONS_PER_CLIENT); retry shortly",
        "errors": [],
    }
).encode()


def _slow_body_answer(rate: float) -> bytes:
    return json.dumps(
        {
            "detail": f"the request body arrived slower than {rate:g} bytes per second after its first "
            f"{BODY_GRACE_S:g} s (COATED_MIN_BODY_RATE)",
            "errors": [],
        }
    ).encode()


def _raw_answer(transport: asyncio.Transport, status: bytes, body: bytes, extra: bytes = b"") -> None:
    """A JSON answer written straight to ``transport``, which is then closed."""
    transport.write(
        b"HTTP/1.1 "
        + status
        + b"\r\ncontent-type: application/json\r\ncontent-length: "
        + str(len(body)).encode()
        + b"\r\nconnection: close\r\n"
        + extra
        + b"\r\n"
        + body
    )
    transport.close()


class DeadlineH11Protocol(H11Protocol):
    """uvicorn's h11 protocol with a deadline on each request's header, a minimum body rate and admission."""

    header_timeout_s = 10.0
    min_body_rate = 1024.0
    max_connections = 512
    max_connections_per_client = 128

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        self._header_deadline: asyncio.TimerHandle | None = None
        self._body_timer: asyncio.TimerHandle | None = None
        self._body_start, self._body_bytes = 0.0, 0
        self._header_seen, self._header_tail = 0, b""
        self._health_only = False
        self.served = False  # a response was sent on it
        super().connection_made(transport)
        admission = self.server_state.coated_admission
        self.host = self.client[0] if self.client else None
        self._admission = admission
        self._touch()
        self._arm_header_deadline()
        if not admission.admit(self, self.loop.time()):
            # Past a bound with none to give way: its request (503, or /healthz) is due within the grace.
            self._health_only = True
            self._disarm_header_deadline()
            self._header_deadline = self.loop.call_later(IDLE_GRACE_S, self._header_timed_out)

    def _touch(self) -> None:
        """Something was sent or received: this connection becomes the most recently active."""
        self.last_active = self.loop.time()
        self._admission.touch(self, self._health_only)

    def close(self) -> None:
        self.transport.close()

    def waiting(self) -> bool:
        """Nothing received on it yet."""
        return self.cycle is None and self.conn.their_state is h11.IDLE and not self.transport.is_closing()

    def idle(self) -> bool:
        """No request in progress on it (and it is not closing), or one whose body is slower than the rate."""
        if self.transport.is_closing():
            return False
        if self.conn.their_state is h11.SEND_BODY and self._body_timer is not None:
            # Behind the rate (no grace here): a trickle reconnected at once is no busier than an idle one.
            return self._body_bytes < self.min_body_rate * (self.loop.time() - self._body_start)
        return self.conn.their_state is h11.IDLE and (self.cycle is None or self.cycle.response_complete)

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
            if self._health_only and not self.served:
                log.warning(OVER_BOUND, IDLE_GRACE_S)
            else:
                log.warning(SLOW_CLIENT, self.header_timeout_s)
            self.transport.close()

    def _body_clock(self, received: int) -> None:
        """Count a body's bytes; start its clock after the header, stop it once the body is whole."""
        if self.conn.their_state is not h11.SEND_BODY:
            if self._body_timer is not None:
                self._body_timer.cancel()
                self._body_timer = None
        elif self._body_timer is None:  # the header is in: count what came with it of the body
            self._body_start, self._body_bytes = self.loop.time(), len(self.cycle.body)
            self._body_timer = self.loop.call_at(self._body_start + BODY_GRACE_S, self._body_check)
        else:
            self._body_bytes += received

    def _body_check(self) -> None:
        """The body's rate: behind it, 408 and the connection closed; else look again when it would be."""
        now = self.loop.time()
        if self.flow.read_paused:  # the service is not reading (the app has not taken what came): not the client's
            self._body_start, self._body_bytes = now, 0
        due = self._body_start + BODY_GRACE_S + self._body_bytes / self.min_body_rate
        if now < due:
            self._body_timer = self.loop.call_at(due, self._body_check)
            return
        self._body_timer = None
        log.warning(SLOW_BODY, self.min_body_rate)
        if self.cycle is not None and not self.cycle.response_started:
            _raw_answer(self.transport, b"408 Request Timeout", _slow_body_answer(self.min_body_rate))
        else:
            self.transport.close()

    def _header_too_large(self, data: bytes) -> bool:
        """Count a header's bytes as they arrive; past the bound answer 431 and close."""
        joined = self._header_tail + data
        end = joined.find(_HEADER_END)
        size = self._header_seen + (len(data) if end < 0 else end + len(_HEADER_END) - len(self._header_tail))
        if size > MAX_HEADER_BYTES:
            _raw_answer(self.transport, b"431 Request Header Fields Too Large", _TOO_LARGE)
            return True
        if end < 0:
            self._header_seen, self._header_tail = size, joined[-3:]
        else:
            self._header_seen, self._header_tail = 0, b""
        return False

    def data_received(self, data: bytes) -> None:
        self._touch()
        if self.conn.their_state is h11.IDLE:
            self._arm_header_deadline()
            start = self._header_tail + data if self._header_seen == 0 else b""
            if self._health_only and len(start) >= len(_HEALTH_REQUESTS[1]) and not start.startswith(_HEALTH_REQUESTS):
                _raw_answer(self.transport, b"503 Service Unavailable", _FULL, b"retry-after: 2\r\n")
                return
            if self._header_too_large(data):
                return
        super().data_received(data)
        if self.conn.their_state is not h11.IDLE:
            self._disarm_header_deadline()
        self._body_clock(len(data))

    def on_response_complete(self) -> None:
        super().on_response_complete()
        self.served = True
        if self._health_only:  # its place in the reserve is for the next probe
            self.transport.close()
            return
        self._touch()
        self._header_seen, self._header_tail = 0, b""
        if self.conn.their_state is h11.IDLE and self.conn.trailing_data[0]:
            self._arm_header_deadline()  # a pipelined request has begun

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm_header_deadline()
        if self._body_timer is not None:
            self._body_timer.cancel()
            self._body_timer = None
        self._admission.discard(self)
        super().connection_lost(exc)


def protocol_with_deadline(
    header_timeout_s: float,
    max_connections: int = 512,
    max_connections_per_client: int = 128,
    min_body_rate: float = 1024.0,
) -> type[DeadlineH11Protocol]:
    """A :class:`DeadlineH11Protocol` subclass with its deadline, body rate and connection bounds set."""
    return type(
        "DeadlineH11Protocol",
        (DeadlineH11Protocol,),
        {
            "header_timeout_s": header_timeout_s,
            "max_connections": max_connections,
            "max_connections_per_client": max_connections_per_client,
            "min_body_rate": min_body_rate,
        },
    )


class _Server(uvicorn.Server):
    """uvicorn's server with this module's admission state shared by its connections (and ``/healthz``)."""

    def __init__(self, config: uvicorn.Config, admission: Admission) -> None:
        super().__init__(config)
        self.server_state.coated_admission = admission


def serve(app, settings: Settings, host: str, port: int) -> None:
    """Run ``app`` on ``host``:``port`` until stopped (SIGINT/SIGTERM)."""
    admission = Admission(settings.max_connections, settings.max_connections_per_client)
    app.state.connections = admission  # /healthz: 503 while every connection is held
    config = uvicorn.Config(
        app,
        host=host,
        port=port,
        log_level="info",
        http=protocol_with_deadline(
            settings.header_timeout_s,
            settings.max_connections,
            settings.max_connections_per_client,
            settings.min_body_rate,
        ),
        # No limit_concurrency: past it uvicorn answers 503 to /healthz too; the admission bounds the connections.
        timeout_keep_alive=settings.keep_alive_s,
        timeout_graceful_shutdown=settings.drain_timeout_s,
        ws="none",
        lifespan="on",
    )
    flood = OncePerInterval()  # after Config, which configures uvicorn's logging
    logging.getLogger("uvicorn.error").addFilter(flood)
    server = _Server(config, admission)
    if threading.current_thread() is threading.main_thread():  # as uvicorn, signals only there
        for signum in (signal.SIGINT, signal.SIGTERM):
            signal.signal(signum, _exit_after_shutdown)
    server.run()


def _exit_after_shutdown(signum: int, frame) -> None:
    """
    The handler of SIGINT and SIGTERM that uvicorn finds, restores after its
    graceful shutdown and calls by raising the signal again: exit with
    status 128 + ``signum`` through ``SystemExit``. The default actions
    skipped the exit handlers: SIGTERM killed the process, so
    multiprocessing's temporary directory (the fork server's socket,
    ``/tmp/pymp-*``) was left behind at every stop, and SIGINT raised
    ``KeyboardInterrupt`` with a traceback.
    """
    raise SystemExit(128 + signum)
