"""
httpx for the tests' own servers on 127.0.0.1 (plain HTTP): ``get``,
``post`` and ``Client`` as httpx's, with one TLS context shared by every
client (:data:`TLS`).

httpx builds a TLS context for each client it makes, even for ``http://``
URLs that never use one (``ssl.create_default_context``: the CA bundle read
and parsed, about 30 ms of CPU each time). The tests made over 1,100 of them
(a top-level ``httpx.get`` is a client of its own; ``ServerProcess.wait_ready``
made one every 50 ms while a server started), over 30 s of CPU on a 2-core
machine, taken from the servers the tests wait for. Each call here is still
a client of its own, with its own connections: only the TLS context is shared.
"""

from __future__ import annotations

import ssl
from typing import Any

import httpx

__all__ = ["TLS", "Client", "get", "post"]

TLS = ssl.create_default_context()
"""The one TLS context (the system's CA bundle, verifying): never used on ``http://``."""


def Client(**kwargs: Any) -> httpx.Client:  # noqa: N802 (httpx's name)
    """``httpx.Client(**kwargs)`` with :data:`TLS`."""
    return httpx.Client(verify=TLS, **kwargs)


def get(url: str, **kwargs: Any) -> httpx.Response:
    """``httpx.get(url, **kwargs)`` with :data:`TLS`."""
    return httpx.get(url, verify=TLS, **kwargs)


def post(url: str, **kwargs: Any) -> httpx.Response:
    """``httpx.post(url, **kwargs)`` with :data:`TLS`."""
    return httpx.post(url, verify=TLS, **kwargs)
