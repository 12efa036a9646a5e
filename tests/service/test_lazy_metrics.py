"""
A fit's metrics cost nothing until asked, and what is derived from a fit is
computed once: an n, k fit answers with what its solve measured, its
evaluation on the metrics grid runs once (asked for, or when the pool is
idle) and is stored; a repeated export download is answered from memory.
"""

from __future__ import annotations

import concurrent.futures
import time

import pytest

from conftest import app_client

API = "/api/v1"
pytestmark = pytest.mark.slow  # the fixtures' fits start the fitting pool's processes


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    # No background evaluation: each evaluation here is one a request asked for.
    with app_client(tmp_path_factory.mktemp("lazy"), metrics_samples=20, metrics_idle_s=0) as client:
        yield client


def test_a_fit_answers_before_its_evaluation_which_runs_once_when_asked(client):
    runner, store = client.app.state.runner, client.app.state.store
    answer = client.post(f"{API}/fits", json={"material": "Cu", "eta_i_range": [1.1, 2.0]})
    assert answer.status_code == 201, answer.text
    fit = answer.json()
    assert fit["metrics"]["evaluated"] is False and fit["metrics"]["figure"] is None
    assert "evaluate" not in fit["timings"]
    assert store.get_fit(fit["id"]).metrics["evaluated"] is False
    # Asked for by several requests at once: one evaluation, shared, stored.
    before = runner.completed
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        answers = list(pool.map(lambda _: client.get(f"{API}/fits/{fit['id']}").json(), range(4)))
    assert runner.completed == before + 1
    figures = [a["metrics"]["figure"] for a in answers]
    assert figures[0]["delta_E_mean"] > 0 and all(f == figures[0] for f in figures)
    assert all(a["metrics"]["evaluated"] is True for a in answers)
    stored = store.get_fit(fit["id"]).metrics
    assert "evaluated" not in stored and stored["figure"] == figures[0] and stored["grid"] == "20x20"
    # Stored: asked again (the fit, its JSON pack, the same fit posted again), nothing runs.
    assert client.get(f"{API}/fits/{fit['id']}/pack?format=json").status_code == 200
    again = client.post(f"{API}/fits?metrics=full", json={"material": "Cu", "eta_i_range": [1.1, 2.0]})
    assert again.status_code == 200 and again.json()["metrics"]["figure"] == figures[0]
    assert runner.completed == before + 1


def test_a_pack_json_waits_for_the_figures_it_quotes(client):
    fit = client.post(f"{API}/fits", json={"material": "Ag"}).json()
    assert fit["metrics"]["evaluated"] is False
    pack = client.get(f"{API}/fits/{fit['id']}/pack?format=json").json()
    figure = pack["materials"][0]["metrics"]["figure"]
    assert figure["delta_E_mean"] > 0
    assert client.get(f"{API}/fits/{fit['id']}").json()["metrics"]["figure"] == figure


def test_metrics_full_answers_with_them(client):
    answer = client.post(f"{API}/fits?metrics=full", json={"material": "Al"})
    assert answer.status_code == 201
    assert answer.json()["metrics"]["evaluated"] is True and answer.json()["metrics"]["model"]["delta_E_mean"] > 0
    bad = client.post(f"{API}/fits?metrics=later", json={"material": "Al"})
    assert bad.status_code == 422 and "metrics" in bad.text


def test_a_repeated_export_is_answered_without_a_job(client):
    runner = client.app.state.runner
    fit = client.post(f"{API}/fits", json={"material": "Au"}).json()
    url = f"{API}/fits/{fit['id']}/pack?format=mtlx&eta_i=1.4"
    first = client.get(url)
    assert first.status_code == 200
    done = runner.completed
    for _ in range(3):
        again = client.get(url)
        assert again.status_code == 200 and again.content == first.content
        assert again.headers["content-disposition"] == first.headers["content-disposition"]
    assert runner.completed == done
    # Another coating index is another export.
    assert client.get(f"{API}/fits/{fit['id']}/pack?format=mtlx&eta_i=1.6").content != first.content
    assert runner.completed == done + 1


def test_the_pool_idle_evaluates_new_fits_in_the_background(tmp_path):
    with app_client(tmp_path, metrics_samples=20, metrics_idle_s=0.2) as client:
        fit = client.post(f"{API}/fits", json={"material": "Ni"}).json()
        assert fit["metrics"]["evaluated"] is False
        store, evaluations = client.app.state.store, client.app.state.evaluations
        deadline = time.monotonic() + 60
        while store.get_fit(fit["id"]).metrics.get("evaluated") is False and time.monotonic() < deadline:
            time.sleep(0.1)
        assert evaluations.done == 1
        assert store.get_fit(fit["id"]).metrics["figure"]["delta_E_mean"] > 0
