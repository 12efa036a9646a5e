"""
``/healthz`` says 503 while this replica cannot fit for anyone: a real
``python -m service`` whose fitting pool can start no worker process (its
fork server and workers killed, and multiprocessing's temporary directory,
where a new fork server's socket goes, made a plain file), then repaired.
"""

from __future__ import annotations

import os
import shutil
import signal
import tempfile
import time
from pathlib import Path

import loopback
import pytest

from conftest import server_process

pytestmark = [pytest.mark.server, pytest.mark.slow]

API = "/api/v1"


def _children(pid: int) -> list[int]:
    parents: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                ppid = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (FileNotFoundError, ProcessLookupError):
                continue
            parents.setdefault(ppid, []).append(int(entry.name))
    return parents.get(pid, [])


def test_healthz_is_503_while_no_fitting_worker_can_start_and_200_once_one_does(tmp_path):
    # The server's own temporary directory, short (a Unix socket's path has at most 107
    # bytes: pytest's tmp_path under a worker's directory can be longer than that allows).
    temporary = Path(tempfile.mkdtemp(prefix="hz-", dir="/tmp"))
    try:
        _check(tmp_path, temporary)
    finally:
        shutil.rmtree(temporary, ignore_errors=True)


def _check(tmp_path, temporary):
    with (
        server_process(tmp_path / "data", TMPDIR=str(temporary)) as server,
        loopback.Client(base_url=server.url, timeout=120) as http,
    ):
        assert http.post(f"{API}/fits", json={"material": "Au"}).status_code == 201
        assert http.get("/healthz").status_code == 200
        (mp_dir,) = temporary.glob("pymp-*")
        shutil.rmtree(mp_dir)
        mp_dir.write_text("not a directory: no fork server's socket can be made here")
        fork_servers = [pid for pid in _children(server.process.pid) if _children(pid)]
        assert fork_servers
        for fork_server in fork_servers:
            for pid in (*_children(fork_server), fork_server):
                os.kill(pid, signal.SIGKILL)
        answer = http.post(f"{API}/fits", json={"material": "Cu"})
        assert answer.status_code == 503 and answer.headers["retry-after"], answer.text
        assert "no fitting worker process could be started" in answer.json()["detail"], answer.text
        health = http.get("/healthz")
        assert health.status_code == 503 and "could be started" in health.json()["detail"], health.text
        assert int(health.headers["retry-after"]) >= 1
        assert http.get(f"{API}/materials").status_code == 200  # what needs no fit is still served
        # Repaired: a probe's background try starts the workers, and the replica is ready again.
        mp_dir.unlink()
        mp_dir.mkdir()
        deadline = time.monotonic() + 60
        while (health := http.get("/healthz")).status_code != 200:
            assert time.monotonic() < deadline, health.text
            time.sleep(0.25)
        assert http.post(f"{API}/fits", json={"material": "Cu"}).status_code == 201
