"""
Faults against the service: host allow-list, slow clients,
paged listing, storage faults, worker death, generated code and ids, edits
in scenes and float32 bounds. Server tests run a real ``python -m service``
on 127.0.0.1; every loop is bounded.
"""

from __future__ import annotations

import ast
import os
import re
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import loopback
import numpy as np
import pytest

from conftest import ROOT, app_client, run_command, server_process

API = "/api/v1"


def gold_like_nk(shift: float = 0.0) -> dict:
    wavelength = np.linspace(350.0, 850.0, 26)
    n = 0.2 + 1.3 * np.exp(-(((wavelength - 350.0) / 150.0) ** 2)) + shift
    k = 1.8 + 4.0 * (wavelength - 350.0) / 500.0
    return {"wavelength_nm": wavelength.tolist(), "n": n.tolist(), "k": k.tolist()}


# -- 3. DNS rebinding ---------------------------------------------------------


@pytest.mark.slow  # 4.8 s (all cases 4.8 s) in a --durations=0 run
@pytest.mark.server
def test_rebinding_host_refused_400_loopback_allowed(tmp_path):
    with server_process(tmp_path / "data") as server:
        evil = {"Host": f"attacker.example:{server.port}", "Origin": f"http://attacker.example:{server.port}"}
        with loopback.Client(base_url=server.url, timeout=60) as http:
            write = http.post(f"{API}/fits", json={"material": "Au"}, headers=evil)
            assert write.status_code == 400
            assert write.headers["content-type"] == "application/json"
            assert "COATED_ALLOWED_HOSTS" in write.json()["detail"]
            assert http.get(f"{API}/materials", headers={"Host": "attacker.example"}).status_code == 400
            for host in (f"localhost:{server.port}", f"127.0.0.1:{server.port}", "LOCALHOST"):
                assert http.get("/healthz", headers={"Host": host}).status_code == 200
            listed = http.get(f"{API}/materials").json()["materials"]
            assert not [m for m in listed if m["latest_fit_id"]]


def test_allowed_hosts_configured(tmp_path):
    from service.api.middleware import host_allowed

    assert host_allowed("[::1]:8000", ("localhost",)) and host_allowed("127.0.0.5", ("localhost",))
    assert host_allowed("api.example.com", (".example.com",)) and not host_allowed("example.org", (".example.com",))
    assert not host_allowed("", ("localhost",))
    with app_client(tmp_path, allowed_hosts=["fresnel.example"]) as client:
        assert client.get("/healthz").status_code == 400  # testserver is no longer allowed
        assert client.get("/healthz", headers={"Host": "fresnel.example"}).status_code == 200


# -- 4. slow clients ------------------------------------------------------------


@pytest.mark.slow  # 6.2 s (all cases 6.2 s) in a --durations=0 run
@pytest.mark.server
def test_slow_clients_are_cut_off_and_healthz_answers(tmp_path):
    with server_process(tmp_path / "data", COATED_HEADER_TIMEOUT_S="1", COATED_BODY_TIMEOUT_S="1") as server:
        slow = []
        for _ in range(40):
            sock = socket.create_connection(("127.0.0.1", server.port), timeout=10)
            sock.sendall(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # header never finished
            slow.append(sock)
        body = socket.create_connection(("127.0.0.1", server.port), timeout=10)
        body.sendall(
            b"POST /api/v1/fits HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
            b"Content-Length: 100\r\n\r\n{"
        )
        started = time.monotonic()
        assert loopback.get(f"{server.url}/healthz", timeout=5).status_code == 200
        answer = b""
        while chunk := body.recv(4096):  # the server closes the connection after its answer
            answer += chunk
        assert b" 408 " in answer.split(b"\r\n")[0] and b"COATED_BODY_TIMEOUT_S" in answer
        assert time.monotonic() - started < 10
        closed = 0
        for sock in slow:
            sock.settimeout(5)
            try:
                closed += sock.recv(1) == b""
            except (ConnectionResetError, socket.timeout):
                closed += 1
            sock.close()
        body.close()
        assert closed == len(slow)
        time.sleep(0.5)
        log = server.log_text()
        assert log.count("did not arrive within 1 s") == 1  # the flood is logged once


# -- 5. paged listing -----------------------------------------------------------


def test_materials_paged_by_summary(tmp_path):
    from service.store import FitRecord, SQLiteStore

    store = SQLiteStore(tmp_path / "data" / "store.sqlite3")
    material = {
        "name": "m",
        "degree": 2,
        "eta_i_range": [1.0, 2.5],
        "source": "",
        "coefficients": {"F0": [[0.5] * 3] * 3, "a": [[0.0] * 3] * 3, "alpha": [[1.0] * 3] * 3},
    }
    for i in range(30):
        store.put_fit(
            FitRecord(
                id=f"{i:032x}", kind="nk", material_id=f"{i + 100:032x}", name=f"m{i}", source="s", material=material
            )
        )
    store.close()
    with app_client(tmp_path, materials_page_max=12) as client:
        first = client.get(f"{API}/materials", params={"kind": ["library", "nk"]}).json()
        from fitting.optics.catalogue import catalogue

        library = sum(entry["preferred"] for entry in catalogue().values())  # each conductor's preferred page
        assert len(first["materials"]) == library + 12 and first["next_cursor"] is not None
        names, cursor = [m["name"] for m in first["materials"][library:]], first["next_cursor"]
        for _ in range(10):
            page = client.get(f"{API}/materials", params={"cursor": cursor, "limit": 12, "kind": "nk"}).json()
            assert all(m["kind"] != "library" for m in page["materials"])
            names += [m["name"] for m in page["materials"]]
            cursor = page["next_cursor"]
            if cursor is None:
                break
        assert names == [f"m{i}" for i in range(30)]


# -- 6. storage faults -------------------------------------------------------------


@pytest.mark.slow  # 2.9 s (all cases 2.9 s) in a --durations=0 run
def test_corrupt_record_reported_and_skipped(tmp_path):
    with app_client(tmp_path, metrics_samples=10) as client:
        a = client.post(f"{API}/fits", json={"name": "a", "nk": gold_like_nk(0.0)}).json()
        b = client.post(f"{API}/fits", json={"name": "b", "nk": gold_like_nk(0.1)}).json()
        with sqlite3.connect(tmp_path / "data" / "store.sqlite3") as db:
            db.execute("UPDATE fits SET record = '{broken' WHERE id = ?", (a["id"],))
            db.execute("UPDATE materials SET kind = 'garbage' WHERE material_id = ?", (b["material_id"],))
        damaged = client.get(f"{API}/fits/{a['id']}")
        assert damaged.status_code == 500 and "damaged" in damaged.json()["detail"]
        listing = client.get(f"{API}/materials", params={"kind": "nk"})
        assert listing.status_code == 200
        body = listing.json()
        assert body["skipped"] == [b["material_id"]]
        assert a["material_id"] in [m["id"] for m in body["materials"]]
        assert client.get(f"{API}/fits/{b['id']}").status_code == 200


@pytest.mark.slow  # 3.8 s (all cases 3.8 s) in a --durations=0 run
def test_store_quota_full_507_and_healthz(tmp_path):
    with app_client(tmp_path, metrics_samples=10, store_max_bytes=200_000) as client:
        statuses = []
        for i in range(60):  # each record is several KiB: the quota is reached well within 60
            response = client.post(f"{API}/fits", json={"name": f"m{i}", "nk": gold_like_nk(i / 100)})
            assert response.headers["content-type"] == "application/json"
            statuses.append(response.status_code)
            if response.status_code == 507:
                break
        assert statuses[-1] == 507 and set(statuses[:-1]) == {201}
        assert "COATED_STORE_MAX_BYTES" in response.json()["detail"]
        health = client.get("/healthz").json()
        assert health["store_writable"] is False and "quota" in health["store_problem"]
        for i, status in enumerate(statuses[:-1]):  # every acknowledged save is there
            assert client.get(f"{API}/materials").status_code == 200
        uploads = client.get(f"{API}/materials", params={"kind": "nk"}).json()["materials"]
        assert len([m for m in uploads if m["kind"] == "nk"]) == len(statuses) - 1


def test_disk_below_free_space_refused_507_before_fitting(tmp_path):
    free = os.statvfs(tmp_path).f_bavail * os.statvfs(tmp_path).f_frsize
    with app_client(tmp_path, store_min_free_bytes=free * 2 + 10**9) as client:
        assert client.get("/healthz").json()["store_writable"] is False
        response = client.post(f"{API}/fits", json={"material": "Au"})
        assert response.status_code == 507 and "nothing was fitted" in response.json()["detail"]
        assert client.app.state.runner.completed == 0


def test_read_only_store_503(tmp_path):
    with app_client(tmp_path) as client:
        store = client.app.state.store
        path = store.path

        def read_only():
            return sqlite3.connect(f"file:{path}?mode=ro", uri=True, check_same_thread=False)

        store._connection = read_only  # the store as SQLite sees a read-only file
        health = client.get("/healthz").json()
        assert health["store_writable"] is False and "readonly" in health["store_problem"]
        response = client.post(f"{API}/fits", json={"material": "Au"})
        assert response.status_code == 503 and response.json()["detail"]


@pytest.mark.slow  # starts a process or GL context
@pytest.mark.parametrize("damage", ["corrupt", "not a directory"])
def test_bad_store_at_start_up_exits_with_one_line(tmp_path, damage):
    data = tmp_path / "data"
    if damage == "corrupt":
        data.mkdir()
        (data / "store.sqlite3").write_bytes(b"this is not a database" * 200)
    else:
        data.write_text("a file where the directory should be")
    result = run_command("service", "--data-dir", str(data), "--port", "0", timeout=120)
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("python -m service: cannot start: the store")
    assert "Traceback" not in result.stderr


@pytest.mark.slow  # starts a process
@pytest.mark.server
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_stopped_server_exits_with_the_signal_s_status_and_leaves_no_temporary_files(tmp_path, signum):
    """
    A stop (SIGTERM from a supervisor, Ctrl-C) shuts down gracefully and then
    exits through Python's exit handlers, with status 128 + the signal.
    Before, uvicorn re-raised the signal under its default action: SIGTERM
    killed the process, leaving multiprocessing's directory of the fork
    server's socket (``pymp-*``) in the temporary directory at every stop,
    and SIGINT ended in a ``KeyboardInterrupt`` traceback.
    """
    # Not under tmp_path: the fork server's socket path must fit a Unix socket's 107 bytes (next test).
    with tempfile.TemporaryDirectory(prefix="coated-") as temporary:
        with server_process(tmp_path / "data", TMPDIR=temporary) as server:
            assert list(Path(temporary).glob("pymp-*")), "the fork server (started at once) has its directory"
            server.process.send_signal(signum)
            assert server.process.wait(timeout=60) == 128 + signum
            log = server.log_text()
        assert "Application shutdown complete" in log and "Traceback" not in log
        assert list(Path(temporary).iterdir()) == []


@pytest.mark.slow  # starts a process
@pytest.mark.server
def test_a_temporary_directory_too_long_for_the_fork_server_s_socket_stops_the_start_with_one_line(tmp_path):
    temporary = tmp_path / ("t" * 90)  # its fork server's socket: pymp-XXXXXXXX/listener-XXXXXXXX in it
    temporary.mkdir()
    run = run_command(
        "service", "--port", "0", "--data-dir", str(tmp_path / "data"), env={**os.environ, "TMPDIR": str(temporary)}
    )
    assert run.returncode == 1
    assert run.stderr.startswith("python -m service: cannot start: the fork server's socket, "), run.stderr
    assert "a Unix socket's path has at most 107: set TMPDIR to a shorter directory" in run.stderr
    assert "Traceback" not in run.stderr and len(run.stderr.splitlines()) == 1
    assert list(temporary.iterdir()) == []  # multiprocessing's directory removed at the exit


@pytest.mark.parametrize("where", ["main thread", "other thread"])
def test_serve_sets_its_stop_handlers_in_the_main_thread_only(monkeypatch, tmp_path, where):
    """
    serve() installs the exit-after-shutdown handlers where signals can be
    handled (Python's main thread, as uvicorn does); an application that
    runs it on another thread keeps its own handlers and gets no error.
    """
    import threading

    import uvicorn

    from service.runtime import server as server_module
    from service.config import Settings
    from service.main import create_app

    monkeypatch.setattr(uvicorn.Server, "run", lambda self, sockets=None: None)
    settings = Settings(data_dir=tmp_path / "data", warm_pool=False, freeze_heap=False)
    before = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    errors = []

    def body():
        try:
            server_module.serve(create_app(settings), settings, "127.0.0.1", 0)
        except BaseException as error:  # reported below, with the thread done
            errors.append(error)

    try:
        if where == "main thread":
            body()
        else:
            thread = threading.Thread(target=body)
            thread.start()
            thread.join(60)
        assert errors == []
        after = {signum: signal.getsignal(signum) for signum in before}
        if where == "main thread":
            assert all(handler is server_module._exit_after_shutdown for handler in after.values())
        else:
            assert after == before
    finally:
        for signum, handler in before.items():
            signal.signal(signum, handler)


# -- 7. worker death -------------------------------------------------------------


def _children(pid: int) -> list[int]:
    out = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True).stdout
    return [int(p) for p in out.split()]


def _worker_pids(server_pid: int) -> list[int]:
    """
    The server's fitting workers: the children of its fork server
    (:func:`service.runtime.worker.process_context`), itself a child of the server
    (a fork of it, :func:`service.runtime.fork_server.start_fork_server`), as is
    multiprocessing's resource tracker, which has none.
    """
    return [worker for child in _children(server_pid) for worker in _children(child)]


def _fork_servers(server_pid: int) -> list[int]:
    """The server's children that have children: its fork server (the resource tracker has none)."""
    return [child for child in _children(server_pid) if _children(child)]


@pytest.mark.slow  # 13.1 s (all cases 13.1 s) in a --durations=0 run
@pytest.mark.server
def test_worker_kill_fails_at_most_its_own_job_and_restart_keeps_saves(tmp_path):
    with server_process(tmp_path / "data", COATED_FIT_WORKERS="2") as server:
        # The workers are found before the fits are sent (the server warms its
        # pool before it answers), so that the kill follows the sight of jobs in
        # flight at once: two `ps` runs between them, on a loaded machine, once
        # outlasted the last fits (a fraction of a second each on warm workers), and a worker killed idle
        # breaks the pool only for the next job. Six fits on two workers leave
        # a few of them queued or running when it lands.
        workers = _worker_pids(server.process.pid)
        assert workers
        fits = 6
        with loopback.Client(base_url=server.url, timeout=120) as http, ThreadPoolExecutor(fits) as pool:
            futures = [
                pool.submit(http.post, f"{API}/fits", json={"name": f"k{i}", "nk": gold_like_nk(i / 50)})
                for i in range(fits)
            ]
            deadline = time.monotonic() + 60
            while http.get("/healthz").json()["fits_in_flight"] < 2 and time.monotonic() < deadline:
                time.sleep(0.01)
            os.kill(workers[0], signal.SIGKILL)
            answers = [f.result() for f in futures]
            assert all(a.headers["content-type"] == "application/json" for a in answers)
            assert [a.status_code for a in answers].count(201) >= fits - 1, [a.text for a in answers]
            health = http.get("/healthz").json()
            assert health["pool_restarts"] == 1
            after = http.post(f"{API}/fits", json={"name": "after", "nk": gold_like_nk(0.3)})
            assert after.status_code == 201
            saved = {a.json()["id"] for a in answers if a.status_code == 201} | {after.json()["id"]}
        server.kill()
    with server_process(tmp_path / "data") as again, loopback.Client(base_url=again.url, timeout=60) as http:
        for fit_id in saved:
            assert http.get(f"{API}/fits/{fit_id}").status_code == 200


def _cmdline(pid: int) -> bytes:
    return Path(f"/proc/{pid}/cmdline").read_bytes()


def _threads(pid: int) -> int:
    status = Path(f"/proc/{pid}/status").read_text()
    return int(re.search(r"^Threads:\s+(\d+)", status, re.M).group(1))


def test_the_fork_server_is_forked_only_where_multiprocessing_would_start_the_same():
    from multiprocessing.forkserver import ForkServer

    from service.runtime.fork_server import _cannot_fork_server

    assert _cannot_fork_server(ForkServer(), 1) is None
    assert "2 Python threads run" in _cannot_fork_server(ForkServer(), 2)
    running = ForkServer()
    running._forkserver_pid = os.getpid()
    assert _cannot_fork_server(running, 1) == "a fork server runs already"
    newer = ForkServer()  # as Python 3.14's, which authenticates its clients
    newer._forkserver_authkey = None
    assert "_forkserver_authkey" in _cannot_fork_server(newer, 1)


@pytest.mark.slow
@pytest.mark.server
def test_the_fork_server_is_a_fork_of_the_server_and_if_it_dies_multiprocessing_starts_its_own(tmp_path):
    with (
        server_process(tmp_path / "data", COATED_FIT_WORKERS="2") as server,
        loopback.Client(base_url=server.url, timeout=120) as http,
    ):
        # Started before the first thread (service.runtime.fork_server.start_fork_server): the server's own
        # command line, one thread, and the workers are its forks.
        fork_servers = _fork_servers(server.process.pid)
        assert len(fork_servers) == 1
        fork_server = fork_servers[0]
        assert _cmdline(fork_server) == _cmdline(server.process.pid)
        assert _threads(fork_server) == 1
        workers = _children(fork_server)
        assert len(workers) == 3  # two workers and the express worker, warmed before the server answered
        assert all(_cmdline(worker) == _cmdline(server.process.pid) for worker in workers)
        assert http.post(f"{API}/fits", json={"name": "first", "nk": gold_like_nk(0.1)}).status_code == 201
        # Killed with its workers: the pool breaks, and the next one's workers come from the fork
        # server multiprocessing starts (a new interpreter importing service.runtime.preload).
        for pid in (fork_server, *workers):
            os.kill(pid, signal.SIGKILL)
        # The job that finds the pool broken runs once more, on the new one (service.runtime.pool).
        after = http.post(f"{API}/fits", json={"name": "after", "nk": gold_like_nk(0.2)})
        assert after.status_code == 201, after.text
        # Once for the workers' death; once more when the killed fork server had not yet exited as the
        # new pool started its workers (its start failed; tested alone below), which the log says.
        starts_failed = server.log.read_text(errors="replace").count("could not be started (its fork server died)")
        assert starts_failed <= 1 and http.get("/healthz").json()["pool_restarts"] == 1 + starts_failed
        fork_servers = _fork_servers(server.process.pid)
        assert len(fork_servers) == 1 and fork_servers[0] != fork_server
        assert b"from multiprocessing.forkserver import main" in _cmdline(fork_servers[0])
        assert b"service.runtime.preload" in _cmdline(fork_servers[0])


def _run_script(script: str, *args: str, env: dict | None = None, timeout_s: float) -> dict:
    """Run ``script`` (``python -c``, in the repository) in a process of its own; the dict its last line prints."""
    run = subprocess.run(
        [sys.executable, "-c", script, *args], cwd=ROOT, env=env, capture_output=True, text=True, timeout=timeout_s
    )
    assert run.returncode == 0, run.stderr[-3000:]
    return ast.literal_eval(run.stdout.strip().splitlines()[-1])


DYING_FORK_SERVER = r"""
import asyncio, os, socket, subprocess, sys, tempfile, threading, time
from multiprocessing import forkserver

import service.runtime.fork_server
from service.runtime.pool import FitRunner, WorkersNotStarted
from service.runtime.previews import PreviewRunner, RenderWorkerLost


def dying_fork_server(exit_after_s):
    # What a killed fork server is until its exit is seen: a process that waitpid finds alive (it is
    # SLEEP's), and a socket that closes every request unanswered.
    address = os.path.join(tempfile.mkdtemp(), "listener")
    listener = socket.socket(socket.AF_UNIX)
    listener.bind(address)
    listener.listen()

    def close_every_request():
        while True:
            connection, _ = listener.accept()
            connection.close()

    threading.Thread(target=close_every_request, daemon=True).start()
    exiting = subprocess.Popen(["sleep", str(exit_after_s)])
    server = forkserver._forkserver
    server._forkserver_address, server._forkserver_alive_fd = address, os.pipe()[1]
    server._forkserver_pid = exiting.pid
    return exiting


async def main():
    runner = FitRunner(1, 4, timeout_s=60.0)
    runner._executor()  # the context's fork server set-up (its preload) happens here
    dying = dying_fork_server(0.5)
    started = time.monotonic()
    pid = await runner.run(os.getpid)
    waited = time.monotonic() - started
    fit = {"worker": pid, "waited_s": waited, "restarts": runner.restarts,
           "fork_server_is_new": forkserver._forkserver._forkserver_pid not in (None, dying.pid)}
    runner.close()

    previews = PreviewRunner(1, timeout_s=60.0, cpu_limit_s=60.0)
    dying = dying_fork_server(0.5)
    try:
        await previews.preview(("a",), os.getpid)
        first = "answered"
    except RenderWorkerLost as error:
        first = str(error)
    second = await previews.preview(("b",), os.getpid)
    previews.close()
    fork_server_is_new = forkserver._forkserver._forkserver_pid not in (None, dying.pid)

    # One that does not exit (within a bound shortened from 5 s): three failed starts, then a 503.
    service.runtime.fork_server.FORK_SERVER_EXIT_S = 0.2
    runner = FitRunner(1, 4, timeout_s=60.0)
    dying = dying_fork_server(60)
    try:
        await runner.run(os.getpid)
        stuck = "answered"
    except WorkersNotStarted as error:
        stuck = f"{error} (Retry-After {error.retry_after}), restarts {runner.restarts}"
    dying.kill()  # reaped by multiprocessing, as a fork server is
    again = await runner.run(os.getpid)
    runner.close()
    return {"fit": fit, "preview_first": first, "preview_second": second, "fork_server_is_new": fork_server_is_new,
            "stuck": stuck, "again": again}


print(repr(asyncio.run(main())))
"""


@pytest.mark.slow
def test_a_worker_start_that_a_dying_fork_server_refuses_waits_for_its_exit_and_starts_from_a_new_one():
    # A fork server killed (with its workers, or by the OOM killer) is seen alive by multiprocessing
    # until its exit ends, and closes the next start's request unanswered (EOFError): that start once
    # ended in a 500 ("internal error (EOFError)") in the fork server test above.
    seen = _run_script(DYING_FORK_SERVER, timeout_s=120)
    fit = seen["fit"]
    assert fit["worker"] != os.getpid() and fit["worker"] > 0, seen
    # Waited for the exit (0.5 s), then one restart onto multiprocessing's new fork server.
    assert fit["waited_s"] >= 0.4 and fit["restarts"] == 1 and fit["fork_server_is_new"], seen
    # A preview's start: that preview is answered 503 (RenderWorkerLost), the next renders.
    assert "could not be started (its fork server died)" in seen["preview_first"], seen
    assert seen["preview_second"] > 0 and seen["fork_server_is_new"], seen
    # A fork server that stays unreachable: 503 (WorkersNotStarted) after three failed starts, not quarantined;
    # once it has exited, the next fit runs.
    assert seen["stuck"] == (
        "no fitting worker process could be started (their fork server died); try again (Retry-After 1), restarts 3"
    ), seen
    assert seen["again"] > 0, seen


KILLED_WHILE_SENDING = r"""
import os, signal, threading, time


def wchar():
    with open("/proc/self/io") as io:
        return next(int(line.split()[1]) for line in io if line.startswith("wchar:"))


def result_killed_while_sent_once(marker, size):
    # SIZE bytes; the first call's worker is SIGKILLed as soon as it has written anything: the header of
    # its result (a result of over 16 KB is sent in two writes, and wchar counts a write when it returns),
    # while the payload's write (64 KB at a time as the pool reads it, milliseconds) goes on.
    payload = b"x" * size
    if not os.path.exists(marker):
        open(marker, "w").close()
        start = wchar()

        def kill_while_sending():
            while wchar() == start:
                time.sleep(0.0002)
            os.kill(os.getpid(), signal.SIGKILL)

        threading.Thread(target=kill_while_sending, daemon=True).start()
    return payload
"""

STUCK_POOLS = r"""
import asyncio, os, sys, time

from killed_while_sending import result_killed_while_sent_once as job
from service.runtime.pool import FitRunner
from service.runtime.previews import PreviewRunner, RenderWorkerLost

SIZE = 64 << 20
here = sys.argv[1]


async def main():
    runner = FitRunner(1, 4, timeout_s=60.0)
    started = time.monotonic()
    sent = await runner.run(job, os.path.join(here, "fit"), SIZE)
    fit = {"bytes": len(sent), "seconds": time.monotonic() - started, "restarts": runner.restarts}
    runner.close()

    previews = PreviewRunner(1, timeout_s=60.0, cpu_limit_s=60.0)
    started = time.monotonic()
    try:
        await previews.preview(("a",), job, os.path.join(here, "preview"), SIZE)
        first = "answered"
    except RenderWorkerLost as error:
        first = str(error)
    first_s = time.monotonic() - started
    second = await previews.preview(("b",), job, os.path.join(here, "preview"), SIZE)
    previews.close()
    return {"fit": fit, "preview_first": first, "preview_first_s": first_s, "preview_second": len(second)}


print(repr(asyncio.run(main())))
"""


@pytest.mark.slow
def test_a_worker_killed_while_it_sends_a_result_does_not_hang_its_pool(tmp_path):
    # Python's ProcessPoolExecutor waits forever for the rest of a result whose worker was killed while
    # it wrote it (service.runtime.executors); the job then runs again as after any worker's death (fit), or is
    # answered 503 and the next renders (preview). Without the watch, the script hangs (its timeout).
    (tmp_path / "killed_while_sending.py").write_text(KILLED_WHILE_SENDING)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (str(tmp_path), os.environ.get("PYTHONPATH"))))}
    seen = _run_script(STUCK_POOLS, str(tmp_path), env=env, timeout_s=150)
    assert (tmp_path / "fit").exists() and (tmp_path / "preview").exists(), seen  # each was killed once
    assert seen["fit"]["bytes"] == 64 << 20 and seen["fit"]["restarts"] == 1, seen
    assert "the render process of this preview died" in seen["preview_first"], seen
    assert seen["preview_second"] == 64 << 20, seen
    # Unstuck after the worker had been dead service.runtime.executors.STUCK_S (3 s), well within the 60 s limit.
    assert seen["fit"]["seconds"] < 30 and seen["preview_first_s"] < 30, seen


@pytest.mark.slow
def test_timed_out_fit_is_cancelled_and_its_worker_freed(tmp_path):
    # A job whose request was answered 504 no longer runs on. The job must outlast the
    # limit and the workers' 0.1 s checks on any machine: 400 x 400 metrics take 0.9 s of the job here
    # (a fit with 10 took 0.05 s on a warm worker, and passed only while a fresh worker's start made
    # up the rest).
    with app_client(tmp_path, fit_timeout_s=0.2, metrics_samples=400) as client:
        body = {"name": "slow", "nk": gold_like_nk(0.2)}
        first = client.post(f"{API}/fits", json=body)
        assert first.status_code == 504 and int(first.headers["retry-after"]) >= 1
        runner = client.app.state.runner
        deadline = time.monotonic() + 1.0
        while runner.in_flight and time.monotonic() < deadline:
            time.sleep(0.02)
        assert runner.in_flight == 0
        assert runner.completed == 0  # cancelled, not finished


# -- 8. generated code and ids ---------------------------------------------------


@pytest.mark.slow  # 2.9 s (all cases 2.9 s) in a --durations=0 run
def test_symbols_unique_and_every_download_compiles(tmp_path):
    with app_client(tmp_path, metrics_samples=10) as client:
        ids = [
            client.post(f"{API}/fits", json={"name": name, "nk": gold_like_nk(i / 10)}).json()["id"]
            for i, name in enumerate(["material x", "x F0", "x"])
        ]
        sources = {
            fmt: client.post(f"{API}/packs", json={"fit_ids": ids, "format": fmt}).text for fmt in ("glsl", "hlsl")
        }
    glsl = sources["glsl"]
    functions = re.findall(r"vec3 (cf_material_\w+)\(float NdotV", glsl)
    assert len(functions) == 3
    for head in ("#version 330\n", "#version 300 es\nprecision highp float;\n"):
        path = tmp_path / "pack.frag"
        path.write_text(
            head
            + glsl
            + "\nout vec4 o;\nvoid main() { o = vec4(%s, 1.0); }\n" % " + ".join(f"{f}(0.5, 1.5)" for f in functions)
        )
        result = subprocess.run(["glslangValidator", str(path)], capture_output=True, text=True, timeout=60)
        assert result.returncode == 0, head + result.stdout
    hlsl = sources["hlsl"]
    calls = " + ".join(f"{f}(0.5, 1.5)" for f in re.findall(r"float3 (cf_material_\w+)\(float NdotV", hlsl))
    path = tmp_path / "pack.hlsl"
    path.write_text(hlsl + "\nfloat4 main() : SV_Target { return float4(%s, 1.0); }\n" % calls)
    result = subprocess.run(
        ["glslangValidator", "-D", "-V", "-S", "frag", "-e", "main", "-o", str(tmp_path / "p.spv"), str(path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stdout


# -- 9. edits in scenes, float32 bounds --------------------------------------------


@pytest.mark.slow  # 3.6 s (all cases 3.6 s) in a --durations=0 run
def test_scene_uses_the_edited_model(tmp_path):
    with app_client(tmp_path, metrics_samples=10) as client:
        edit = {
            "name": "warm gold",
            "base": {"material": "Au"},
            "curves": [
                {
                    "eta_i": 1.5,
                    "angle_deg": [0, 30, 60, 75, 90],
                    "rgb": [[0.2, 0.9, 0.2], [0.2, 0.9, 0.2], [0.2, 0.88, 0.22], [0.3, 0.85, 0.4], [1, 1, 1]],
                }
            ],
        }
        edited = client.post(f"{API}/fits/from-curves", json=edit)
        assert edited.status_code == 201, edited.text
        fit = edited.json()
        scene = client.post(
            f"{API}/scenes", json={"materials": [{"name": "w", "material": fit["material_id"], "eta_i": 1.5}]}
        )
        assert scene.status_code == 200, scene.text
        report = scene.json()["materials"][0]
        assert report["fit"]["from_stored_model"] is True and report["material"] == fit["material_id"]
        shipped = scene.json()["pack"]["materials"][0]["coefficients"]
        assert shipped == fit["coefficients"]  # the edits, not gold's n, k
        outside = client.post(
            f"{API}/scenes", json={"materials": [{"name": "w", "material": fit["material_id"], "eta_i": 2.9}]}
        )
        assert outside.status_code == 422 and "materials[0].eta_i" in outside.json()["detail"]


@pytest.mark.slow  # 2.8 s (all cases 2.8 s) in a --durations=0 run
def test_edit_at_the_float32_rounded_upper_end(tmp_path):
    with app_client(tmp_path, metrics_samples=10) as client:
        base = client.post(f"{API}/fits", json={"material": "Cu", "eta_i_range": [2.9999999, 3.0]})
        assert base.status_code == 201, base.text
        edit = {
            "name": "edge",
            "base": {"fit": base.json()["id"]},
            "eta_i_range": [2.9999999, 3.0],
            "curves": [
                {
                    "eta_i": 2.9999999,
                    "cos_theta": [1.0, 0.7, 0.4, 0.1, 0.0],
                    "rgb": [[0.9, 0.6, 0.5], [0.9, 0.6, 0.5], [0.9, 0.62, 0.52], [0.93, 0.8, 0.75], [1, 1, 1]],
                }
            ],
        }
        response = client.post(f"{API}/fits/from-curves", json=edit)
        assert response.status_code == 201, response.text


# -- a client that goes away cancels its job ------------------------------


@pytest.mark.slow
@pytest.mark.server
def test_a_job_whose_client_went_away_is_cancelled_within_a_second(tmp_path):
    import json

    scene = {
        "name": "big",
        "materials": [
            {"name": f"m{i}", "nk": gold_like_nk(i / 100), "eta_i": np.linspace(1.0, 2.5, 32).tolist()}
            for i in range(64)
        ],
    }
    payload = json.dumps(scene).encode()
    with server_process(tmp_path / "data") as server, loopback.Client(base_url=server.url, timeout=30) as http:
        with socket.create_connection(("127.0.0.1", server.port), timeout=10) as raw:
            raw.sendall(
                b"POST /api/v1/scenes HTTP/1.1\r\nHost: 127.0.0.1\r\ncontent-type: application/json\r\n"
                + f"content-length: {len(payload)}\r\n\r\n".encode()
                + payload
            )
            deadline = time.monotonic() + 30
            while http.get("/healthz").json()["fits_in_flight"] == 0 and time.monotonic() < deadline:
                time.sleep(0.05)
            assert http.get("/healthz").json()["fits_in_flight"] == 1
        gone = time.monotonic()  # the client closed its connection
        while http.get("/healthz").json()["fits_in_flight"] and time.monotonic() - gone < 10:
            time.sleep(0.05)
        assert time.monotonic() - gone < 1.5
        # The worker is free: the next fit is answered at once.
        t0 = time.monotonic()
        assert http.post(f"{API}/fits", json={"material": "Cu"}).status_code in (200, 201)
        assert time.monotonic() - t0 < 10
