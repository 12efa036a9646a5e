"""
Against a real ``python -m service`` process on 127.0.0.1: start-up,
concurrency, overload, a SIGKILL during saves, and the schemathesis fuzz run.
"""

from __future__ import annotations

import itertools
import sqlite3
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import httpx
import loopback
import numpy as np
import pytest
import schemathesis
from hypothesis import HealthCheck, given, settings
from hypothesis.errors import Unsatisfiable
from schemathesis.checks import (
    content_type_conformance,
    not_a_server_error,
    response_headers_conformance,
    response_schema_conformance,
    status_code_conformance,
)

from conftest import run_command, server_process

API = "/api/v1"
pytestmark = pytest.mark.server


def gold_like_nk(shift: float) -> dict:
    wavelength = np.linspace(350.0, 850.0, 26)
    n = 0.2 + 1.3 * np.exp(-(((wavelength - 350.0) / 150.0) ** 2)) + shift
    k = 1.8 + 4.0 * (wavelength - 350.0) / 500.0
    return {"wavelength_nm": wavelength.tolist(), "n": n.tolist(), "k": k.tolist()}


def test_start_up_and_docs(tmp_path):
    """The command itself (``python -m service``, as README starts it; other tests' servers are forks)."""
    with (
        server_process(tmp_path / "data", spawn=True) as server,
        loopback.Client(base_url=server.url, timeout=30) as http,
    ):
        assert server.process.args[:3] == [sys.executable, "-m", "service"]
        assert http.get("/healthz").json()["status"] == "ok"
        assert http.get("/openapi.json").json()["info"]["title"]
        assert "swagger" in http.get("/docs").text.lower()
        fit = http.post(f"{API}/fits", json={"material": "Au"})
        assert fit.status_code == 201
        pack = http.get(f"{API}/fits/{fit.json()['id']}/pack")
        assert pack.status_code == 200 and pack.content[:4] == b"CFPK"


def test_refuses_public_bind_without_token(tmp_path):
    result = run_command("service", "--host", "0.0.0.0", "--data-dir", str(tmp_path), timeout=120)
    assert result.returncode == 2
    assert "COATED_API_TOKEN" in result.stderr


def test_concurrent_identical_fits_and_reads(tmp_path):
    with server_process(tmp_path / "data", COATED_FIT_WORKERS="2") as server:
        with loopback.Client(base_url=server.url, timeout=120) as http, ThreadPoolExecutor(8) as pool:
            fits = [pool.submit(http.post, f"{API}/fits", json={"material": "Cu"}) for _ in range(4)]
            others = [
                pool.submit(http.post, f"{API}/fits", json={"material": "Ag", "eta_i_range": [1.0, 1.0 + i / 10]})
                for i in range(1, 4)
            ]
            reads = [pool.submit(http.get, f"{API}/materials") for _ in range(8)]
            answers = [f.result() for f in fits]
            assert all(a.status_code in (200, 201) for a in answers)
            assert len({a.json()["id"] for a in answers}) == 1
            assert all(r.result().status_code == 200 for r in reads)
            assert all(f.result().status_code == 201 for f in others)
            latest = http.get(f"{API}/materials/Cu").json()["latest_fit"]
            assert latest["id"] == answers[0].json()["id"]
            eta = sorted(f.result().json()["eta_i_range"][1] for f in others)
            np.testing.assert_allclose(eta, [1.1, 1.2, 1.3], rtol=1e-6)  # float32 in
            # the pack: u32 = 6e-8 relative, 17x inside 1e-6


def test_overload_answers_503_not_a_backlog(tmp_path):
    with server_process(tmp_path / "data", COATED_FIT_QUEUE="0") as server:
        barrier = threading.Barrier(6)

        def fit(i: int) -> httpx.Response:
            with loopback.Client(base_url=server.url, timeout=120) as http:
                barrier.wait()
                return http.post(f"{API}/fits", json={"material": "Fe", "eta_i_range": [1.0, 1.5 + i / 10]})

        with ThreadPoolExecutor(6) as pool:
            answers = list(pool.map(fit, range(6)))
        codes = sorted(a.status_code for a in answers)
        assert 201 in codes and 503 in codes and set(codes) <= {201, 503}, codes
        for answer in answers:
            if answer.status_code == 503:
                assert int(answer.headers["retry-after"]) >= 1
                assert "retry" in answer.json()["detail"]


def test_saves_survive_sigkill(tmp_path):
    data = tmp_path / "data"
    answered: dict[str, dict] = {}
    lock = threading.Lock()
    with server_process(data, COATED_FIT_WORKERS="2", COATED_METRICS_SAMPLES="10") as server:
        stop = threading.Event()

        def save(client: int) -> None:
            with loopback.Client(base_url=server.url, timeout=60) as http:
                for j in range(1000):
                    if stop.is_set():
                        return
                    body = {"name": f"client {client} save {j}", "nk": gold_like_nk(0.01 * client)}
                    try:
                        response = http.post(f"{API}/fits", json=body)
                    except httpx.TransportError:
                        return  # the server died mid-request: this save was never answered
                    if response.status_code in (200, 201):
                        with lock:
                            answered[response.json()["id"]] = response.json()["coefficients"]

        threads = [threading.Thread(target=save, args=(i,)) for i in range(3)]
        for thread in threads:
            thread.start()
        deadline = time.monotonic() + 180
        while len(answered) < 8 and time.monotonic() < deadline:
            time.sleep(0.05)
        server.kill()
        stop.set()
        for thread in threads:
            thread.join()
    assert len(answered) >= 8
    with sqlite3.connect(data / "store.sqlite3") as connection:
        assert connection.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
    with server_process(data) as server, loopback.Client(base_url=server.url, timeout=30) as http:
        for fit_id, coefficients in answered.items():
            response = http.get(f"{API}/fits/{fit_id}")
            assert response.status_code == 200, fit_id
            assert response.json()["coefficients"] == coefficients
        listed = http.get(f"{API}/materials", params={"kind": "nk"}).json()["materials"]  # n, k fits
        saved = {m["latest_fit_id"] for m in listed}
        assert set(answered) <= saved


def test_fuzz_no_server_error_no_schema_violation(tmp_path):
    """
    Schemathesis against the service's own OpenAPI document: per operation,
    20 valid cases and 20 invalid ones (where the schema allows invalid input).
    """
    with server_process(tmp_path / "data", COATED_METRICS_SAMPLES="10", COATED_MAX_PREVIEW_SIZE="128") as server:
        schema = schemathesis.openapi.from_url(f"{server.url}/openapi.json")
        operations = [result.ok() for result in schema.get_all_operations()]
        assert len(operations) >= 10
        for operation, mode in itertools.product(operations, schemathesis.GenerationMode):

            @given(case=operation.as_strategy(generation_mode=mode))
            @settings(
                max_examples=20, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True, database=None
            )
            def fuzz(case):
                case.call_and_validate(
                    checks=[
                        not_a_server_error,
                        status_code_conformance,
                        content_type_conformance,
                        response_headers_conformance,
                        response_schema_conformance,
                    ],
                    timeout=60,
                )

            try:
                fuzz()
            except Unsatisfiable:
                assert mode is schemathesis.GenerationMode.NEGATIVE, operation.label
