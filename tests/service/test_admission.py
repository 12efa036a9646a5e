"""
Connection admission against a real ``python -m service``
on 127.0.0.1. A flood of idle connections only churns itself (a new
connection closes the longest idle one), one address cannot hold more than
its share, ``/healthz`` is answered even when every connection is busy, and
a burst past the bound is answered 503 rather than cut. Every socket is
closed at the end; every loop is bounded.
"""

from __future__ import annotations

import contextlib
import socket
import statistics
import threading
import time

import httpx
import loopback
import pytest

from conftest import server_process

from service.runtime.server import BODY_GRACE_S, IDLE_GRACE_S

pytestmark = [pytest.mark.slow, pytest.mark.server]


def idle_sockets(port: int, count: int, source: str = "127.0.0.1") -> list[socket.socket]:
    out = []
    for _ in range(count):
        s = socket.create_connection(("127.0.0.1", port), timeout=5, source_address=(source, 0))
        out.append(s)
    return out


def still_open(sockets, settle_s: float = 0.3) -> int:
    """Sockets the server has not closed (a closed one reads b'' at once), after ``settle_s``."""
    time.sleep(settle_s)
    count = 0
    for s in sockets:
        s.setblocking(False)
        try:
            count += s.recv(1) != b""
        except BlockingIOError:
            count += 1
        except OSError:
            pass
    return count


def test_healthz_answers_fast_with_600_idle_connections_open(tmp_path):
    with server_process(tmp_path / "data", COATED_WARM_POOL="false") as server, contextlib.ExitStack() as stack:
        flood = idle_sockets(server.port, 600)
        for s in flood:
            stack.callback(s.close)
        seconds = []
        for _ in range(60):
            t0 = time.perf_counter()
            response = loopback.get(f"{server.url}/healthz", timeout=10)  # a new connection each time
            seconds.append(time.perf_counter() - t0)
            assert response.status_code == 200, response.text
        # The sample's 99th percentile, between its two largest of 60 (numpy's default, as
        # test_previews_bounded.py). The default "exclusive" method extrapolates past the largest:
        # one slow request of 0.44 s among 0.035 s ones made a "p99" of 0.598 s, and a failure.
        p99 = statistics.quantiles(seconds, n=100, method="inclusive")[98]
        assert p99 < 0.5, (p99, max(seconds))
        # COATED_MAX_CONNECTIONS_PER_CLIENT: those past it close when their first request's grace is over.
        assert still_open(flood, IDLE_GRACE_S + 0.3) <= 128


def test_one_address_cannot_shut_out_another(tmp_path):
    with (
        server_process(tmp_path / "data", COATED_WARM_POOL="false", COATED_MAX_CONNECTIONS_PER_CLIENT="20") as server,
        contextlib.ExitStack() as stack,
    ):
        flood = idle_sockets(server.port, 60)
        for s in flood:
            stack.callback(s.close)
        assert still_open(flood, IDLE_GRACE_S + 0.3) <= 20
        transport = httpx.HTTPTransport(local_address="127.0.0.2")
        with loopback.Client(transport=transport, timeout=10) as other:
            assert other.get(f"{server.url}/api/v1/materials").status_code == 200


@contextlib.contextmanager
def bodies_at_the_rate(busy: list[socket.socket]):
    """``busy`` connections whose bodies trickle 5 B/s (a rate of 2 B/s is asked) while the block runs."""
    for s in busy:
        s.sendall(
            b"POST /api/v1/fits HTTP/1.1\r\nHost: 127.0.0.1\r\ncontent-type: application/json\r\n"
            b"content-length: 1000\r\n\r\n"
        )
    trickling = threading.Event()
    trickling.set()

    def trickle() -> None:
        while trickling.is_set():
            for s in busy:
                s.sendall(b" ")
            time.sleep(0.2)

    thread = threading.Thread(target=trickle)
    thread.start()
    try:
        time.sleep(BODY_GRACE_S + 0.5)  # past the grace, at the rate: busy
        yield busy
    finally:
        trickling.clear()
        thread.join()


def test_with_every_connection_busy_healthz_answers_503_and_slow_bodies_are_answered_408(tmp_path):
    """Eight bodies at the rate hold every connection: /healthz is answered, 503 naming why, and a library
    request 503; once they stop each is answered 408 within the rate's allowance and /healthz is 200 again."""
    with (
        server_process(
            tmp_path / "data", COATED_WARM_POOL="false", COATED_MAX_CONNECTIONS="8", COATED_MIN_BODY_RATE="2"
        ) as server,
        contextlib.ExitStack() as stack,
    ):
        busy = idle_sockets(server.port, 8)
        stack.callback(lambda: [s.close() for s in busy])
        with bodies_at_the_rate(busy):
            health = loopback.get(f"{server.url}/healthz", timeout=10)
            assert health.status_code == 503 and "COATED_MAX_CONNECTIONS" in health.json()["detail"], health.text
            assert health.headers["retry-after"] == "2"
            refused = loopback.get(f"{server.url}/api/v1/materials", timeout=10)
            assert refused.status_code == 503 and "COATED_MAX_CONNECTIONS" in refused.json()["detail"]
            assert still_open(busy) == 8  # busy connections are never evicted
        answers = []
        for s in busy:  # behind the rate from now: 408 within the allowance earned (a few seconds) and the grace
            s.settimeout(15)
            answers.append(s.recv(65536))
        assert all(a.startswith(b"HTTP/1.1 408 ") and b"COATED_MIN_BODY_RATE" in a for a in answers), answers
        assert loopback.get(f"{server.url}/healthz", timeout=10).status_code == 200


def test_with_an_address_s_every_connection_busy_its_healthz_is_answered(tmp_path):
    with (
        server_process(
            tmp_path / "data", COATED_WARM_POOL="false", COATED_MAX_CONNECTIONS_PER_CLIENT="4", COATED_MIN_BODY_RATE="2"
        ) as server,
        contextlib.ExitStack() as stack,
    ):
        busy = idle_sockets(server.port, 4, "127.0.0.2")
        stack.callback(lambda: [s.close() for s in busy])
        with bodies_at_the_rate(busy):
            transport = httpx.HTTPTransport(local_address="127.0.0.2", verify=loopback.TLS)
            with httpx.Client(transport=transport, timeout=10) as same:
                assert same.get(f"{server.url}/healthz").status_code == 200  # the replica serves others
            with httpx.Client(
                transport=httpx.HTTPTransport(local_address="127.0.0.2", verify=loopback.TLS), timeout=10
            ) as same:
                assert same.get(f"{server.url}/api/v1/materials").status_code == 503
            assert loopback.get(f"{server.url}/api/v1/materials", timeout=10).status_code == 200


def test_a_burst_past_the_bound_is_answered_503_not_cut(tmp_path):
    """60 connections from one address at once, each sending its request at
    once, against a bound of 20: every one gets an answer, 200 or 503 with
    Retry-After (before, the burst's new connections closed its earlier
    ones, whose requests were still on their way: connection resets)."""
    with (
        server_process(tmp_path / "data", COATED_WARM_POOL="false", COATED_MAX_CONNECTIONS_PER_CLIENT="20") as server,
        contextlib.ExitStack() as stack,
    ):
        sockets = idle_sockets(server.port, 60)
        for s in sockets:
            stack.callback(s.close)
        answers: list[bytes] = [b""] * len(sockets)

        def ask(i: int, s: socket.socket) -> None:
            try:
                s.sendall(b"GET /api/v1/materials HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
                s.settimeout(10)
                while b"\r\n\r\n" not in answers[i]:
                    chunk = s.recv(65536)
                    if not chunk:
                        break
                    answers[i] += chunk
            except OSError as error:  # a reset
                answers[i] = repr(error).encode()

        threads = [threading.Thread(target=ask, args=(i, s)) for i, s in enumerate(sockets)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        status = [a.split(b"\r\n", 1)[0] for a in answers]
        assert all(line in (b"HTTP/1.1 200 OK", b"HTTP/1.1 503 Service Unavailable") for line in status), status
        assert status.count(b"HTTP/1.1 200 OK") >= 20
        refused = [a for a in answers if a.startswith(b"HTTP/1.1 503")]
        assert refused and all(b"retry-after: 2" in a.lower() for a in refused)


def test_a_connection_past_the_bound_closes_the_one_idle_longest(tmp_path):
    """The longest idle is counted from each connection's last activity, not from its opening."""
    with (
        server_process(tmp_path / "data", COATED_WARM_POOL="false", COATED_MAX_CONNECTIONS_PER_CLIENT="3") as server,
        contextlib.ExitStack() as stack,
    ):
        first, second, third = idle_sockets(server.port, 3)
        for s in (first, second, third):
            stack.callback(s.close)
        first.settimeout(10)
        first.sendall(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")  # kept alive after its answer
        answer = b""
        while b"\r\n\r\n" not in answer:
            answer += first.recv(65536)
        assert answer.startswith(b"HTTP/1.1 200 OK"), answer
        time.sleep(IDLE_GRACE_S + 0.3)  # all three idle past the grace; `second` the longest
        fourth = idle_sockets(server.port, 1)[0]
        stack.callback(fourth.close)
        assert still_open([second]) == 0
        assert still_open([first, third, fourth]) == 3
