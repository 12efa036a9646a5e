"""
Drafts as references, with a life, against a real
``python -m service`` on 127.0.0.1. A draft refers to the stored record
holding its n, k (100 live steps on a 20,000-sample upload add under 2 MB);
on an inline n, k (item 2's rest) to that n, k stored once as a
content-addressed n, k record (100 live steps on a 20,000-sample inline
base add under 2 MB too); drafts past their time to live, or past the
drafts' quota, are removed in the background with the n, k records no fit
refers to any more, saved fits never.
"""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import threading
import time
from pathlib import Path

import loopback
import numpy as np
import pytest

from conftest import server_process

pytestmark = [pytest.mark.slow, pytest.mark.server]
API = "/api/v1"
ANGLE = np.linspace(0.0, 90.0, 31)


def big_nk(samples=20_000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    wavelength = np.linspace(300.0, 900.0, samples)
    n = 0.2 + 1.3 * np.exp(-(((wavelength - 350.0) / 150.0) ** 2))
    k = 1.8 + 4.0 * (wavelength - 300.0) / 600.0
    return wavelength, n, k


def big_csv(samples=20_000) -> bytes:
    """A 20,000-sample n, k upload (CSV, under the upload limit)."""
    rows = "".join(f"{w:.4f},{a:.6f},{b:.6f}\n" for w, a, b in zip(*big_nk(samples)))
    return ("wavelength_nm,n,k\n" + rows).encode()


def inline_nk(samples=20_000) -> dict:
    """The same n, k as an inline base, with the upload's digits (all 17 of each float64 would take
    the body past COATED_MAX_BODY_BYTES at 20,000 samples)."""
    wavelength, n, k = big_nk(samples)
    return {
        "wavelength_nm": np.round(wavelength, 4).tolist(),
        "n": np.round(n, 6).tolist(),
        "k": np.round(k, 6).tolist(),
    }


def step(base_id, start, value, live=True, inline=None, name="dragged"):
    """A live step (a draft) on the stored fit ``base_id``, or on the ``inline`` base; not live and
    on an inline base: a save."""
    rgb = np.full((ANGLE.size, 3), 0.6)
    rgb[:, 1] = value
    return {
        "name": name,
        "base": inline or {"fit": base_id},
        "draft": live or inline is None,
        "live": live,
        **({"start_fit": start} if live and start else {}),
        "curves": [{"eta_i": 1.5, "angle_deg": ANGLE.tolist(), "rgb": rgb.tolist()}],
    }


def encoded(body: dict, base_json: str) -> dict:
    """
    ``httpx`` arguments posting ``body`` as JSON with its ``base`` the
    already encoded ``base_json``: a 20,000-sample inline base is nearly all
    of a step's 0.6 MB, so the test encodes it once, not at every step (the
    server parses each step's whole body either way).
    """
    text = json.dumps({**body, "base": None}, separators=(",", ":"))
    assert text.count('"base":null') == 1
    return {
        "content": text.replace('"base":null', f'"base":{base_json}').encode(),
        "headers": {"content-type": "application/json"},
    }


def stored_bytes(data_dir):
    """The bytes of every stored record: fits and n, k records."""
    with sqlite3.connect(data_dir / "store.sqlite3") as db:
        return db.execute(
            "SELECT (SELECT coalesce(sum(length(record)), 0) FROM fits) + "
            "(SELECT coalesce(sum(length(record)), 0) FROM nk_records)"
        ).fetchone()[0]


def counted(data_dir, sql):
    with sqlite3.connect(data_dir / "store.sqlite3") as db:
        return db.execute(sql).fetchone()[0]


def test_100_live_steps_on_a_20000_sample_upload_add_under_2_mb(tmp_path):
    data = tmp_path / "data"
    with server_process(data) as server, loopback.Client(base_url=server.url, timeout=120) as http:
        base = http.post(f"{API}/fits/upload", files={"file": ("big.csv", big_csv(), "text/csv")})
        assert base.status_code == 201, base.text[:300]
        base_id = start = base.json()["id"]
        before = stored_bytes(data)
        for i in range(100):
            answer = http.post(f"{API}/fits/from-curves", json=step(base_id, start, 0.5 + 0.002 * i))
            assert answer.status_code == 201, answer.text[:300]
            start = answer.json()["id"]
        grown = stored_bytes(data) - before
        assert grown < 2_000_000, grown
        # The draft still has its n, k (through its reference): curves against the measured data.
        fit = http.get(f"{API}/fits/{start}").json()
        assert fit["has_nk"] is True
        curves = http.get(f"{API}/fits/{start}/curves", params={"eta_i": 1.5})
        assert curves.status_code == 200, curves.text[:300]


def test_100_live_steps_on_a_20000_sample_inline_base_add_under_2_mb(tmp_path):
    data = tmp_path / "data"
    base = {"nk": inline_nk()}
    base_json = json.dumps(base, separators=(",", ":"))
    with server_process(data) as server, loopback.Client(base_url=server.url, timeout=120) as http:
        before = stored_bytes(data)
        start = None
        for i in range(100):
            answer = http.post(
                f"{API}/fits/from-curves", **encoded(step(None, start, 0.5 + 0.002 * i, inline=base), base_json)
            )
            assert answer.status_code == 201, answer.text[:300]
            start = answer.json()["id"]
        grown = stored_bytes(data) - before
        print(f"100 live steps on a 20,000-sample inline base: {grown} bytes")
        assert grown < 2_000_000, grown
        # One n, k record, content-addressed, that the 100 drafts refer to.
        assert counted(data, "SELECT count(*) FROM nk_records") == 1
        assert counted(data, "SELECT count(DISTINCT nk_id) FROM fits WHERE nk_id IS NOT NULL") == 1
        assert counted(data, "SELECT count(*) FROM fits WHERE nk_id IS NOT NULL") == 100
        # The draft has its n, k (through the record): curves against the measured data.
        fit = http.get(f"{API}/fits/{start}").json()
        assert fit["has_nk"] is True
        assert http.get(f"{API}/fits/{start}/curves", params={"eta_i": 1.5}).status_code == 200
        # Neither the n, k record nor the drafts are materials, saved or uploaded.
        listed = http.get(f"{API}/materials", params={"kind": ["nk", "curves"]}).json()["materials"]
        assert not [m for m in listed if m["name"].startswith("dragged")], listed
        # A save of the edit keeps its n, k in its own record, as every saved fit.
        saved = http.post(f"{API}/fits/from-curves", json=step(None, None, 0.7, live=False, inline=base))
        assert saved.status_code == 201, saved.text[:300]
        assert counted(data, f"SELECT nk_id IS NULL FROM fits WHERE id = '{saved.json()['id']}'") == 1
        assert http.get(f"{API}/fits/{saved.json()['id']}").json()["has_nk"] is True


def test_an_inline_base_expires_with_its_drafts(tmp_path):
    data = tmp_path / "data"
    base = {"nk": inline_nk(2_000)}
    with (
        server_process(data, COATED_DRAFT_TTL_S="3", COATED_DRAFT_SWEEP_S="0.5") as server,
        loopback.Client(base_url=server.url, timeout=120) as http,
    ):
        start = None
        for i in range(3):
            answer = http.post(f"{API}/fits/from-curves", json=step(None, start, 0.5 + 0.01 * i, inline=base))
            assert answer.status_code == 201, answer.text[:300]
            start = answer.json()["id"]
        assert counted(data, "SELECT count(*) FROM nk_records") == 1
        deadline = time.monotonic() + 20
        while counted(data, "SELECT count(*) FROM nk_records") and time.monotonic() < deadline:
            time.sleep(0.25)
        assert counted(data, "SELECT count(*) FROM nk_records") == 0  # gone with its drafts
        assert http.get(f"{API}/fits/{start}").status_code == 404


def test_drafts_expire_and_count_against_their_quota(tmp_path):
    data = tmp_path / "data"
    with (
        server_process(data, COATED_DRAFT_TTL_S="3", COATED_DRAFT_SWEEP_S="0.5") as server,
        loopback.Client(base_url=server.url, timeout=120) as http,
    ):
        base = http.post(f"{API}/fits", json={"material": "Au"}).json()["id"]
        draft = http.post(f"{API}/fits/from-curves", json=step(base, None, 0.5, live=False))
        assert draft.status_code == 201, draft.text[:300]
        draft_id = draft.json()["id"]
        assert http.get(f"{API}/fits/{draft_id}").status_code == 200
        deadline = time.monotonic() + 20
        while http.get(f"{API}/fits/{draft_id}").status_code == 200 and time.monotonic() < deadline:
            time.sleep(0.25)
        assert http.get(f"{API}/fits/{draft_id}").status_code == 404
        assert http.get(f"{API}/fits/{base}").status_code == 200  # saved fits never expire
    with (
        server_process(tmp_path / "quota", COATED_DRAFT_MAX_BYTES="20000", COATED_DRAFT_SWEEP_S="0.5") as server,
        loopback.Client(base_url=server.url, timeout=120) as http,
    ):
        base = http.post(f"{API}/fits", json={"material": "Au"}).json()["id"]
        # Live steps: drafts as the save above is one, without its full refit each.
        ids = [
            http.post(f"{API}/fits/from-curves", json=step(base, None, 0.3 + 0.05 * i)).json()["id"] for i in range(6)
        ]
        deadline = time.monotonic() + 20  # a sweep every 0.5 s
        while http.get(f"{API}/fits/{ids[0]}").status_code == 200 and time.monotonic() < deadline:
            time.sleep(0.1)
        kept = [http.get(f"{API}/fits/{i}").status_code == 200 for i in ids]
        assert kept[-1] and not kept[0], kept  # the oldest went first
        assert stored_bytes(tmp_path / "quota") - 0 < 200_000


def test_a_draft_a_saved_material_or_a_link_refers_to_outlives_its_time_to_live(tmp_path):
    data = tmp_path / "data"
    # Made under the default time to live (a save is a full refit: tens of seconds on a busy machine) ...
    with server_process(data) as server, loopback.Client(base_url=server.url, timeout=120) as http:
        base = http.post(f"{API}/fits", json={"material": "Au"}).json()["id"]
        # The drafts are live steps (a draft without a save's full refit); the save on one is a full refit.
        on_draft, loose, linked = (
            http.post(f"{API}/fits/from-curves", json=step(base, None, value)).json()["id"]
            for value in (0.50, 0.55, 0.60)
        )
        saved = http.post(
            f"{API}/fits/from-curves",
            json={**step(on_draft, None, 0.45, live=False), "draft": False, "name": "saved on a draft"},
        )
        assert saved.status_code == 201, saved.text[:300]
        saved_id = saved.json()["id"]
        time.sleep(1.0)
        link = http.post(f"{API}/fits/{linked}/link")
        assert link.status_code == 200, link.text
        created = http.get(f"{API}/fits/{linked}").json()["created_at"]
        assert link.json()["draft"] and link.json()["expires_at"] >= created + 86_400 + 1.0  # from the link
        assert http.post(f"{API}/fits/{saved_id}/link").json() == {
            "fit_id": saved_id,
            "url": f"/?fit={saved_id}",
            "draft": False,
            "expires_at": None,
        }
        assert http.post(f"{API}/fits/{'0' * 32}/link").status_code == 404
    # ... then served with drafts kept 1 s: what nothing refers to goes, the rest stays.
    with (
        server_process(data, COATED_DRAFT_TTL_S="1", COATED_DRAFT_SWEEP_S="0.5") as server,
        loopback.Client(base_url=server.url, timeout=120) as http,
    ):
        deadline = time.monotonic() + 30
        while http.get(f"{API}/fits/{loose}").status_code == 200 and time.monotonic() < deadline:
            time.sleep(0.25)
        assert http.get(f"{API}/fits/{loose}").status_code == 404
        assert http.get(f"{API}/fits/{linked}").status_code == 200  # the link keeps it its day
        # The saved material reopens on its draft base and saves again.
        edit = http.get(f"{API}/fits/{saved_id}/edit").json()
        assert edit["base"] == {"fit": on_draft} and http.get(f"{API}/fits/{on_draft}").status_code == 200
        again = http.post(f"{API}/fits/from-curves", json={**edit["request"], "expected_version": edit["version"]})
        assert again.status_code == 200 and again.json()["id"] == saved_id, again.text[:300]


def _workers(server_pid: int) -> list[int]:
    """The fitting workers (and any other grandchild) of the server: children of its children, from /proc."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                ppid = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (FileNotFoundError, ProcessLookupError):
                continue
            children.setdefault(ppid, []).append(int(entry.name))
    return [pid for child in children.get(server_pid, []) for pid in children.get(child, [])]


def test_a_save_keeps_its_draft_base_while_it_is_fitted(tmp_path):
    # A save on a draft base whose fit outlasts the draft's time to live (its workers stopped, as a
    # loaded machine would delay it): the base is kept from the save's start, the save is answered 201.
    with (
        server_process(tmp_path / "data", COATED_DRAFT_TTL_S="4", COATED_DRAFT_SWEEP_S="0.25") as server,
        loopback.Client(base_url=server.url, timeout=120) as http,
    ):
        base = http.post(f"{API}/fits", json={"material": "Au"}).json()["id"]
        draft = http.post(f"{API}/fits/from-curves", json=step(base, None, 0.5))  # a live step: a draft
        assert draft.status_code == 201, draft.text[:300]
        draft_id, created = draft.json()["id"], http.get(f"{API}/fits/{draft.json()['id']}").json()["created_at"]
        workers = _workers(server.process.pid)
        assert workers
        answers = []
        for pid in workers:
            os.kill(pid, signal.SIGSTOP)
        try:
            body = {**step(draft_id, None, 0.45, live=False), "draft": False, "name": "saved on a short draft"}
            save = threading.Thread(
                target=lambda: answers.append(
                    loopback.post(f"{server.url}{API}/fits/from-curves", json=body, timeout=120)
                )
            )
            save.start()
            deadline = time.monotonic() + 20
            while http.get("/healthz").json()["fits_in_flight"] < 1:  # the save is in the pool, waiting
                assert time.monotonic() < deadline, "the save never reached the pool"
                time.sleep(0.05)
            assert time.time() < created + 4.0, "the save started after its base expired: the test proves nothing"
            time.sleep(max(0.0, created + 4.0 + 1.5 - time.time()))  # past the time to live, and six sweeps
            assert http.get(f"{API}/fits/{draft_id}").status_code == 200  # kept by the save in flight
        finally:
            for pid in workers:
                os.kill(pid, signal.SIGCONT)
        save.join(timeout=120)
        assert answers and answers[0].status_code == 201, answers and answers[0].text[:300]
        saved = answers[0].json()["id"]
        time.sleep(1.0)  # more sweeps: a saved fit's base never expires
        assert http.get(f"{API}/fits/{draft_id}").status_code == 200
        assert http.get(f"{API}/fits/{saved}/edit").json()["base"] == {"fit": draft_id}
