"""
Two service replicas on one PostgreSQL store, as real processes
on loopback ports (``server_process`` with ``COATED_STORE_URL``) against a
real PostgreSQL server the tests start (``postgres_server``):

-   200 saves spread over both replicas: each listed by both, each
    downloadable from the other replica the moment it is answered;
-   20 concurrent saves of one name with ``expected_version`` 0: exactly
    one 201, 19 answers 409; without it: 20 versions, one latest;
-   a save on one replica expecting the version read before a rename or a
    delete on the other: 409 naming what changed;
-   one replica SIGKILLed during a burst of saves: no answered save lost;
-   PostgreSQL restarted under the replicas: 503 with Retry-After while it
    is down (the first answer at once), then both answer again without
    being restarted.
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import httpx
import loopback
import numpy as np
import pytest

from conftest import server_process

API = "/api/v1"
pytestmark = [pytest.mark.xdist_group("postgres"), pytest.mark.slow, pytest.mark.server]


def nk_body(i: int, prefix: str = "r") -> dict:
    wavelength = np.linspace(350.0, 850.0, 26)
    n = 0.2 + 1.3 * np.exp(-(((wavelength - 350.0) / 150.0) ** 2)) + i * 1e-4
    k = 1.8 + 4.0 * (wavelength - 350.0) / 500.0
    return {"name": f"{prefix}{i}", "nk": {"wavelength_nm": wavelength.tolist(), "n": n.tolist(), "k": k.tolist()}}


def curves_body(i: int, name: str, **extra) -> dict:
    """
    An edit saved under ``name``: of the per-channel kind, whose refit is
    about a quarter of the default kind's (these tests are about the store
    shared by two replicas, not about the fit; 40 refits of the default kind
    were most of this module's time).
    """
    g = 0.6 + i * 0.005
    return {
        "name": name,
        "model": "rgb-conductor",
        "base": {"material": "Au"},
        "curves": [
            {
                "eta_i": 1.5,
                "angle_deg": [0, 30, 60, 75, 90],
                "rgb": [[0.9, g, 0.35], [0.9, g, 0.35], [0.88, g, 0.36], [0.85, 0.7, 0.45], [1, 1, 1]],
            }
        ],
        **extra,
    }


def listed(url: str) -> dict[str, dict]:
    """Every saved material (edits and n, k fits) of a replica's listing, by id (all pages)."""
    out, cursor = {}, None
    with loopback.Client(base_url=url, timeout=60) as http:
        for _ in range(100):
            params = [("kind", "curves"), ("kind", "nk"), *([("cursor", cursor)] if cursor is not None else [])]
            page = http.get(f"{API}/materials", params=params).json()
            out.update({m["id"]: m for m in page["materials"] if m["kind"] != "library"})
            cursor = page["next_cursor"]
            if cursor is None:
                return out
    raise AssertionError("the listing did not end within 100 pages")


@pytest.fixture(scope="module")
def replicas(tmp_path_factory, postgres_server):
    """
    Two replicas on one database, shared by the module's tests (a pair takes
    about 16 s to start). Each test saves under names of its own and asserts
    only about what it saved; the test that kills a replica runs last.
    """
    tmp_path = tmp_path_factory.mktemp("replicas")
    url = postgres_server.database("replicas")
    env = {
        "COATED_STORE_URL": url,
        "COATED_METRICS_SAMPLES": "10",
        "COATED_FIT_QUEUE": "64",
        "COATED_STORE_POOL_MAX": "4",
    }
    with server_process(tmp_path / "a", **env) as a, server_process(tmp_path / "b", **env) as b:
        yield a, b


def test_saves_on_either_replica_are_everyone_s(replicas, postgres_server):
    a, b = replicas
    health = loopback.get(f"{a.url}/healthz", timeout=10).json()
    assert health["store"]["kind"] == "postgresql" and health["store"]["connections_max"] == 4
    assert health["store"]["role_connection_limit"] == 40 and health["store"]["server_connection_limit"] == 57
    assert "password" not in str(health) and postgres_server.password not in str(health)
    pairs = [(a, b), (b, a)]
    misses: list[str] = []

    def save(i: int) -> str:
        on, other = pairs[i % 2]
        with loopback.Client(timeout=120) as http:
            answer = http.post(f"{on.url}{API}/fits", json=nk_body(i))
            assert answer.status_code == 201, answer.text
            fit_id = answer.json()["id"]
            # Downloadable from the other replica at once.
            if http.get(f"{other.url}{API}/fits/{fit_id}/pack", params={"format": "binary"}).status_code != 200:
                misses.append(fit_id)
            return answer.json()["material_id"]

    with ThreadPoolExecutor(8) as pool:
        saved = set(pool.map(save, range(200)))
    assert len(saved) == 200 and misses == []
    for replica in (a, b):
        assert saved <= set(listed(replica.url))
    # The same fit on both replicas is one record (ids are content addresses).
    again = [loopback.post(f"{r.url}{API}/fits", json=nk_body(7), timeout=60) for r in (a, b)]
    assert [r.status_code for r in again] == [200, 200] and again[0].json()["id"] == again[1].json()["id"]


def test_same_name_at_once_one_winner(replicas):
    a, b = replicas
    barrier = threading.Barrier(20)

    def save(i: int, body: dict) -> httpx.Response:
        barrier.wait()
        return loopback.post(f"{(a, b)[i % 2].url}{API}/fits/from-curves", json=body, timeout=300)

    with ThreadPoolExecutor(20) as pool:
        answers = list(pool.map(lambda i: save(i, curves_body(i, "contested", expected_version=0)), range(20)))
    codes = sorted(r.status_code for r in answers)
    assert codes == [201] + [409] * 19, [r.text for r in answers if r.status_code not in (201, 409)]
    winner = next(r.json() for r in answers if r.status_code == 201)
    conflict = next(r.json() for r in answers if r.status_code == 409)
    assert "another save came first" in conflict["detail"] and conflict["errors"][0]["loc"] == [
        "body",
        "expected_version",
    ]
    for replica in (a, b):
        detail = loopback.get(f"{replica.url}{API}/materials/{winner['material_id']}", timeout=30).json()
        assert detail["version"] == 1 and detail["latest_fit_id"] == winner["id"]
    # Without `expected_version`: every save is the next version, one is the latest.
    with ThreadPoolExecutor(20) as pool:
        barrier.reset()
        answers = list(pool.map(lambda i: save(i, curves_body(i + 20, "shared")), range(20)))
    assert [r.status_code for r in answers] == [201] * 20
    ids = {r.json()["id"] for r in answers}
    material = answers[0].json()["material_id"]
    views = [loopback.get(f"{r.url}{API}/materials/{material}", timeout=30).json() for r in (a, b)]
    assert views[0] == views[1] and views[0]["version"] == 20 and views[0]["latest_fit_id"] in ids
    stale = loopback.post(
        f"{a.url}{API}/fits/from-curves", json=curves_body(50, "shared", expected_version=3), timeout=60
    )
    assert stale.status_code == 409 and "nothing was fitted" in stale.json()["detail"]


def test_a_stale_save_on_one_replica_does_not_undo_a_rename_or_delete_on_the_other(replicas):
    a, b = replicas
    with loopback.Client(timeout=300) as http:
        first = http.post(f"{a.url}{API}/fits/from-curves", json=curves_body(60, "renamed away")).json()
        material_id = first["material_id"]
        assert http.patch(f"{b.url}{API}/materials/{material_id}", json={"name": "renamed here"}).status_code == 200
        stale = http.post(
            f"{a.url}{API}/fits/from-curves",
            json=curves_body(61, "renamed away", material_id=material_id, expected_version=1),
        )
        assert stale.status_code == 409 and "renamed 'renamed here'" in stale.json()["detail"], stale.text
        assert http.delete(f"{a.url}{API}/materials/{material_id}").status_code == 200
        binned = http.post(
            f"{b.url}{API}/fits/from-curves",
            json=curves_body(61, "renamed here", material_id=material_id, expected_version=1),
        )
        assert binned.status_code == 409 and "moved to the bin" in binned.json()["detail"], binned.text
        assert http.get(f"{a.url}{API}/materials/{material_id}").json()["version"] == 1


def test_postgres_restart_503_then_recovery(replicas, postgres_server):
    a, b = replicas
    before = loopback.post(f"{a.url}{API}/fits", json=nk_body(1, "p"), timeout=120)
    assert before.status_code == 201
    postgres_server.stop()
    try:
        for replica in (a, b):
            start = time.monotonic()
            health = loopback.get(f"{replica.url}/healthz", timeout=30)
            # The first answer after the server went away, at once (the store's QUICK_WAIT_S, then a
            # refused connection), not after the pool timeout (5 s): half of it is the bound.
            assert time.monotonic() - start < 2.5
            assert health.status_code == 503 and 1 <= int(health.headers["retry-after"]) <= 5
            refused = loopback.post(f"{replica.url}{API}/fits", json=nk_body(2, "p"), timeout=60)
            assert refused.status_code == 503 and int(refused.headers["retry-after"]) <= 5
            assert "unavailable" in refused.json()["detail"]
            assert loopback.get(f"{replica.url}{API}/fits/{before.json()['id']}", timeout=30).status_code == 503
    finally:
        postgres_server.start()
    for replica in (a, b):  # recovered by themselves, without a restart
        deadline = time.monotonic() + 30
        while loopback.get(f"{replica.url}/healthz", timeout=30).status_code != 200:
            assert time.monotonic() < deadline, "the replica did not recover within 30 s"
            time.sleep(0.2)
    after = loopback.post(f"{b.url}{API}/fits", json=nk_body(2, "p"), timeout=120)
    assert after.status_code == 201
    assert {before.json()["material_id"], after.json()["material_id"]} <= set(listed(a.url))
    assert a.process.poll() is None and b.process.poll() is None


def test_replica_killed_during_saves_loses_nothing_answered(replicas):
    a, b = replicas
    answered: list[str] = []
    lock = threading.Lock()
    stop = threading.Event()

    def client(replica, start: int) -> None:
        with loopback.Client(base_url=replica.url, timeout=120) as http:
            i = start
            while not stop.is_set() and i < start + 200:
                try:
                    response = http.post(f"{API}/fits", json=nk_body(i, "k"))
                except httpx.TransportError:
                    return  # the killed replica: nothing answered, nothing counted
                if response.status_code == 201:
                    with lock:
                        answered.append(response.json()["id"])
                i += 1

    threads = [threading.Thread(target=client, args=(r, 1000 * (j + 1))) for j, r in enumerate((a, a, b, b))]
    for thread in threads:
        thread.start()
    deadline = time.monotonic() + 120
    while len(answered) < 30 and time.monotonic() < deadline:
        time.sleep(0.05)
    a.kill()
    time.sleep(2.0)
    stop.set()
    for thread in threads:
        thread.join(timeout=180)
    assert len(answered) >= 30
    with loopback.Client(base_url=b.url, timeout=60) as http:
        missing = [fit_id for fit_id in answered if http.get(f"{API}/fits/{fit_id}").status_code != 200]
    assert missing == []
    assert len(listed(b.url)) >= len(set(answered))
