"""
Connections held by hostile clients against a real ``python -m service``
(a body rate of 1024 B/s): request bodies trickling one byte every 5 s
(reconnecting whenever the server closes one) and 600 idle sockets churning
from 127.0.0.3-127.0.0.6 (150 each, the oldest closed and a new one opened
10 times a second per address), while 127.0.0.7 reads the library and the
materials and 127.0.0.1 probes ``/healthz``: 128 trickles from 127.0.0.2
with the default bounds (512 connections, 128 per address), and trickles
from four addresses that fill the bound (at a quarter of the scale). Before
the minimum body rate the trickles held their connections for the whole
body deadline (30 s), and from four addresses filled the server's bound:
another address had 10 of 72 requests answered and ``/healthz`` was reset
25 of 72 times.
Every socket is closed at the end; every loop is bounded in time.
"""

from __future__ import annotations

import collections
import contextlib
import selectors
import socket
import threading
import time

import httpx
import loopback
import pytest

from conftest import server_process

pytestmark = [pytest.mark.slow, pytest.mark.server]

TRICKLE_HEADER = (
    b"POST /api/v1/fits HTTP/1.1\r\nHost: 127.0.0.1\r\ncontent-type: application/json\r\ncontent-length: 1000\r\n\r\n"
)


def _connect(port: int, source: str) -> socket.socket | None:
    try:
        return socket.create_connection(("127.0.0.1", port), timeout=5, source_address=(source, 0))
    except OSError:
        return None


def _trickle(port: int, source: str, count: int, stop: threading.Event, closed: list[int]) -> None:
    """``count`` bodies from ``source``, a byte every 5 s each; one the server closes is opened again."""
    selector = selectors.DefaultSelector()
    next_byte = time.monotonic() + 5

    def open_one() -> None:
        s = _connect(port, source)
        if s is not None:
            s.sendall(TRICKLE_HEADER)
            s.setblocking(False)
            selector.register(s, selectors.EVENT_READ)

    try:
        for _ in range(count):
            open_one()
        while not stop.is_set():
            for key, _ in selector.select(0.1):  # an answer (408) or the connection closed
                s = key.fileobj
                selector.unregister(s)
                closed[0] += 1
                with contextlib.suppress(OSError):
                    closed[1] += s.recv(4096).startswith(b"HTTP/1.1 408 ")
                s.close()
                open_one()
            if time.monotonic() >= next_byte:
                next_byte += 5
                for key in list(selector.get_map().values()):
                    with contextlib.suppress(OSError):
                        key.fileobj.send(b" ")
    finally:
        for key in list(selector.get_map().values()):
            key.fileobj.close()
        selector.close()


def _churn(port: int, source: str, stop: threading.Event) -> None:
    """150 idle sockets from ``source``: the oldest closed and a new one opened, 10 times a second."""
    sockets = collections.deque(s for s in (_connect(port, source) for _ in range(150)) if s is not None)
    try:
        while not stop.is_set():
            if sockets:
                sockets.popleft().close()
            s = _connect(port, source)
            if s is not None:
                sockets.append(s)
            stop.wait(0.1)
    finally:
        for s in sockets:
            s.close()


def _probe(url: str, stop: threading.Event, answers: list) -> None:
    """``/healthz`` from 127.0.0.1 on a new connection every 0.25 s: its status, or the error."""
    while not stop.is_set():
        try:
            answers.append(loopback.get(f"{url}/healthz", timeout=10).status_code)
        except httpx.HTTPError as error:
            answers.append(repr(error))
        stop.wait(0.25)


@pytest.mark.parametrize(
    "trickles, bounds",
    [
        pytest.param({"127.0.0.2": 128}, {}, id="128-trickles-from-one-address"),
        # The bound filled with trickles from four addresses, at a quarter of the scale (before: 503 to others).
        pytest.param(
            {f"127.0.0.{i}": 16 for i in range(2, 6)},
            {"COATED_MAX_CONNECTIONS": "64", "COATED_MAX_CONNECTIONS_PER_CLIENT": "16"},
            id="the-bound-filled-with-trickles",
        ),
    ],
)
def test_trickling_bodies_and_churning_idle_sockets_leave_another_address_served(tmp_path, trickles, bounds):
    with server_process(tmp_path / "data", COATED_WARM_POOL="false", **bounds) as server:
        stop = threading.Event()
        closed = [0, 0]  # trickles closed, of them answered 408
        probes: list = []
        threads = [
            threading.Thread(target=_trickle, args=(server.port, source, count, stop, closed))
            for source, count in trickles.items()
        ]
        threads += [threading.Thread(target=_churn, args=(server.port, f"127.0.0.{i}", stop)) for i in range(3, 7)]
        try:
            for t in threads:
                t.start()
            time.sleep(3)  # the floods in place: 128 bodies, 600 idle sockets, the first trickles closed
            threads.append(threading.Thread(target=_probe, args=(server.url, stop, probes)))
            threads[-1].start()
            answered, failed = 0, []
            transport = httpx.HTTPTransport(local_address="127.0.0.7")
            with loopback.Client(transport=transport, timeout=10) as reader:
                for i in range(40):
                    path = "/api/v1/library" if i % 2 else "/api/v1/materials"
                    try:
                        response = reader.get(f"{server.url}{path}")
                        if response.status_code == 200:
                            answered += 1
                        else:
                            failed.append((response.status_code, response.text[:150]))
                    except httpx.HTTPError as error:
                        failed.append(repr(error))
                    time.sleep(0.1)
        finally:
            stop.set()
            for t in threads:
                t.join(30)
        assert answered >= 0.95 * 40, (answered, failed)
        assert probes and all(p == 200 for p in probes), probes
        # Each trickle was closed within seconds: answered 408, or closed for a new connection past a bound.
        assert closed[0] >= sum(trickles.values()), closed
        if not bounds:  # with room for them, past the rate's allowance
            assert closed[1] >= 128, closed
            assert "COATED_MIN_BODY_RATE" in server.log.read_text(errors="replace")  # logged (once a minute)
