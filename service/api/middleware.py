"""
Request middleware
==================

Pure ASGI middleware that answers before the application sees a request:

-   :class:`HostAllowList`: a ``Host`` header not in the allow-list is
    answered 400 (DNS rebinding: a hostile page that makes its own name
    resolve to 127.0.0.1 sends its own name as ``Host``).
-   :class:`RequestLimits`: a body larger than the limit is answered 413,
    and one that arrives slower than the body deadline 408; a client that
    goes away before its answer cancels its request (and the job it waits for).
-   :class:`ClaimWork`: whose work a request is and its kind
    (:data:`service.runtime.shares.CLAIM`), for the fitting pool's fair shares.
-   :class:`FrameDenial`: every answer forbids framing (``X-Frame-Options:
    DENY``, CSP ``frame-ancestors 'none'``): a page framed by another site
    would be same-origin for the editor, and clicks tricked through it
    would pass the Origin check.
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import ipaddress
import json
import re

from fastapi import status
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ..runtime import CLAIM, Claim

__all__ = ["HostAllowList", "RequestLimits", "ClaimWork", "FrameDenial", "host_allowed", "LOOPBACK_HOSTS"]

LOOPBACK_HOSTS = ("localhost", "127.0.0.1", "::1")
"""The default allow-list: names and addresses that only reach this machine."""


async def _refuse(send: Send, status_code: int, detail: str) -> None:
    body = json.dumps({"detail": detail, "errors": []}).encode()
    await send(
        {
            "type": "http.response.start",
            "status": status_code,
            "headers": [
                (b"content-type", b"application/json"),
                (b"content-length", str(len(body)).encode()),
                (b"connection", b"close"),
            ],
        }
    )
    await send({"type": "http.response.body", "body": body})


_PORT = re.compile(r":[0-9]{1,5}", re.ASCII)


def _host_name(host: str) -> str:
    """
    ``Host`` without its port, lower case: ``[::1]:8000`` -> ``::1``; ``""``
    (never allowed) when what follows the name is not ``:`` and digits
    (``[::1]evil.example``, ``localhost:80x``).
    """
    host = host.strip().lower()
    if host.startswith("["):
        name, bracket, rest = host[1:].partition("]")
        return name if bracket and (not rest or _PORT.fullmatch(rest)) else ""
    if host.count(":") == 1:
        host, port = host.split(":", 1)
        if not _PORT.fullmatch(":" + port):
            return ""
    return host.rstrip(".")


def host_allowed(host: str, allowed: tuple[str, ...]) -> bool:
    """
    Whether ``host`` (a ``Host`` header) names one of ``allowed``: exact
    names or addresses, ``.example.com`` for it and its subdomains, ``*``
    for any; ``localhost`` also allows ``*.localhost`` and 127.0.0.0/8.
    """
    name = _host_name(host)
    if not name:
        return False
    for entry in allowed:
        entry = entry.lower()
        if entry == "*" or entry == name:
            return True
        if entry.startswith(".") and (name == entry[1:] or name.endswith(entry)):
            return True
        if entry == "localhost":
            if name.endswith(".localhost"):
                return True
            try:
                if ipaddress.ip_address(name).is_loopback:
                    return True
            except ValueError:
                pass
    return False


class HostAllowList:
    """ASGI middleware: refuse (400, JSON) a request whose ``Host`` is not allowed."""

    def __init__(self, app: ASGIApp, allowed: tuple[str, ...]) -> None:
        self.app = app
        self.allowed = tuple(allowed)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        host = ""
        for key, value in scope.get("headers") or ():
            if key == b"host":
                host = value.decode("latin-1")
                break
        if not host_allowed(host, self.allowed):
            shown = host[:80] if host.isprintable() else repr(host[:80])
            await _refuse(
                send,
                status.HTTP_400_BAD_REQUEST,
                f"the `Host` {shown!r} is not served here: allowed are "
                f"{', '.join(self.allowed)} (COATED_ALLOWED_HOSTS)",
            )
            return
        await self.app(scope, receive, send)


class RequestLimits:
    """
    ASGI middleware: a request body larger than the limit is answered 413
    before the application sees it (``max_upload_bytes`` for the upload
    route, ``max_body_bytes`` elsewhere; Content-Length checked up front,
    streamed bytes counted), and a body not complete within
    ``body_timeout_s`` of the request's start is answered 408.
    """

    def __init__(
        self,
        app: ASGIApp,
        max_body_bytes: int,
        max_upload_bytes: int,
        upload_paths: tuple[str, ...],
        body_timeout_s: float,
    ) -> None:
        self.app = app
        self.max_body_bytes = max_body_bytes
        self.max_upload_bytes = max_upload_bytes
        self.upload_paths = upload_paths
        self.body_timeout_s = body_timeout_s

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        upload = scope["path"] in self.upload_paths
        limit = self.max_upload_bytes if upload else self.max_body_bytes
        setting = "COATED_MAX_UPLOAD_BYTES" if upload else "COATED_MAX_BODY_BYTES"
        headers = dict(scope.get("headers") or [])
        declared = headers.get(b"content-length")
        too_large = f"the request body must be at most {limit} bytes ({setting})"
        if declared is not None and declared.isdigit() and int(declared) > limit:
            await _refuse(send, status.HTTP_413_CONTENT_TOO_LARGE, too_large)
            return
        loop = asyncio.get_running_loop()
        deadline = loop.time() + self.body_timeout_s
        chunks: list[bytes] = []
        size = 0
        while True:
            try:
                message = await asyncio.wait_for(receive(), max(0.0, deadline - loop.time()))
            except asyncio.TimeoutError:
                await _refuse(
                    send,
                    status.HTTP_408_REQUEST_TIMEOUT,
                    f"the request body did not arrive within {self.body_timeout_s:g} s (COATED_BODY_TIMEOUT_S)",
                )
                return
            if message["type"] == "http.disconnect":
                return
            chunk = message.get("body", b"")
            size += len(chunk)
            if size > limit:
                await _refuse(send, status.HTTP_413_CONTENT_TOO_LARGE, too_large)
                return
            chunks.append(chunk)
            if not message.get("more_body", False):
                break
        await _cancel_on_disconnect(self.app, scope, b"".join(chunks), receive, send)


async def _cancel_on_disconnect(app: ASGIApp, scope: Scope, body: bytes, receive: Receive, send: Send) -> None:
    """
    Run ``app`` on the read ``body`` while watching the connection: a client
    that goes away before its answer is complete cancels the request's task
    (and with it the job it waits for, :meth:`service.runtime.pool.FitRunner.once`).
    """
    disconnected = asyncio.Event()
    answered = False
    sent = False

    async def replay() -> Message:
        nonlocal sent
        if not sent:
            sent = True
            return {"type": "http.request", "body": body, "more_body": False}
        await disconnected.wait()
        return {"type": "http.disconnect"}

    async def sending(message: Message) -> None:
        nonlocal answered
        if message["type"] == "http.response.body" and not message.get("more_body", False):
            answered = True
        await send(message)

    async def watch() -> None:
        while (await receive())["type"] != "http.disconnect":
            pass
        disconnected.set()

    task = asyncio.ensure_future(app(scope, replay, sending))
    watcher = asyncio.ensure_future(watch())
    try:
        await asyncio.wait({task, watcher}, return_when=asyncio.FIRST_COMPLETED)
        if not task.done() and not answered:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task
            return
        await task
    except asyncio.CancelledError:
        task.cancel()
        raise
    finally:
        watcher.cancel()


class ClaimWork:
    """
    ASGI middleware: set :data:`service.runtime.shares.CLAIM` for the request. The
    client is ``"token"`` when the request carries the service's bearer
    token (``token``; compared in constant time), else its address; the
    kind is ``save`` for ``POST`` to one of ``save_paths``, ``scene`` and
    ``pack`` for ``POST`` to ``scene_path`` and ``pack_path``, and ``read``
    for anything else.
    """

    def __init__(
        self, app: ASGIApp, token: str | None, save_paths: tuple[str, ...], scene_path: str, pack_path: str
    ) -> None:
        self.app = app
        self.token = f"Bearer {token}".encode() if token else None
        self.kinds = {**dict.fromkeys(save_paths, "save"), scene_path: "scene", pack_path: "pack"}

    def claim(self, scope: Scope) -> Claim:
        kind = self.kinds.get(scope["path"], "read") if scope["method"] == "POST" else "read"
        if self.token is not None:
            given = next((v for k, v in scope["headers"] if k == b"authorization"), b"")
            if hmac.compare_digest(given, self.token):
                return Claim("token", kind)
        client = scope.get("client")
        return Claim(client[0] if client else "unknown", kind)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        token = CLAIM.set(self.claim(scope))
        try:
            await self.app(scope, receive, send)
        finally:
            CLAIM.reset(token)


class FrameDenial:
    """ASGI middleware: ``X-Frame-Options: DENY`` and CSP ``frame-ancestors 'none'`` on every answer."""

    HEADERS = [(b"x-frame-options", b"DENY"), (b"content-security-policy", b"frame-ancestors 'none'")]

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def framed(message: Message) -> None:
            if message["type"] == "http.response.start":
                names = {name.lower() for name, _ in message.get("headers", [])}
                extra = [(n, v) for n, v in self.HEADERS if n not in names]
                message = {**message, "headers": [*message.get("headers", []), *extra]}
            await send(message)

        await self.app(scope, receive, framed)
