"""
tests/server_forks.py: the servers the tests fork from one interpreter
that has imported the service are ``python -m service`` in all but the
imports: their settings come from their environment, each leads a session
of its own with its output in its log, and their exit statuses are
``subprocess.Popen``'s; an environment a fork cannot take starts the
command itself. The commands it forks (``run_command``: ``python -m
fitting``, ``python -m preview_shaders``) are the commands' runs: exit
statuses, standard output and error, working directory and timeout.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import loopback
import pytest
from conftest import ROOT, SERVER_FORKS, run_command, server_process
from server_forks import ForkedProcess, forkable

from benchmarks.server_start import stat_fields

pytestmark = [pytest.mark.server, pytest.mark.slow]

BASE = {"PATH": "/usr/bin", "HOME": "/root", "OPENBLAS_CORETYPE": "Haswell", "COATED_FIT_WORKERS": "1"}


@pytest.mark.parametrize(
    "env, expected",
    [
        (BASE, True),
        ({**BASE, "COATED_FIT_WORKERS": "2", "COATED_FIT_QUEUE": "0"}, True),  # the service's settings
        ({**BASE, "TMPDIR": "/tmp/x"}, True),  # read when first used
        ({**BASE, "PYTEST_CURRENT_TEST": "tests/a.py::t (call)"}, True),
        ({k: v for k, v in BASE.items() if k != "COATED_FIT_WORKERS"}, True),
        ({**BASE, "OPENBLAS_CORETYPE": "Prescott"}, False),  # read by OpenBLAS when numpy is imported
        ({**BASE, "PYTHONHASHSEED": "1"}, False),  # read by the interpreter at its start
        ({k: v for k, v in BASE.items() if k != "PATH"}, False),
    ],
)
def test_a_fork_takes_only_the_service_s_variables(env, expected):
    assert forkable(BASE, env) is expected


def test_a_forked_server_reads_its_settings_leads_its_session_and_exits_as_the_command(tmp_path):
    with (
        server_process(tmp_path / "data", COATED_FIT_WORKERS="3") as server,
        loopback.Client(base_url=server.url, timeout=30) as http,
    ):
        process = server.process
        assert isinstance(process, ForkedProcess)
        health = http.get("/healthz").json()
        assert health["fit_workers"] == 3 and health["store"]["path"].startswith(str(tmp_path / "data"))
        fields = stat_fields(process.pid)
        assert int(fields[3]) == process.pid  # its own session (what start_new_session gives the command)
        assert int(fields[1]) != os.getpid()  # the program's child, not this process's
        assert process.poll() is None
        with pytest.raises(subprocess.TimeoutExpired):
            process.wait(timeout=0.1)
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=60) == 128 + signal.SIGTERM  # as the command's (tests/service/test_faults.py)
        assert process.poll() == 128 + signal.SIGTERM
    assert "GET /healthz" in server.log.read_text()  # its output went to its log


def test_a_forked_server_that_cannot_start_says_why_with_the_command_s_status(tmp_path):
    (tmp_path / "data").write_text("not a directory")
    with pytest.raises(RuntimeError, match=r"exited with 1:\s+python -m service: cannot start: the store"):
        with server_process(tmp_path / "data"):
            pass


def test_an_environment_a_fork_cannot_take_starts_the_command(tmp_path):
    with (
        server_process(tmp_path / "data", PYTHONHASHSEED="7") as server,
        loopback.Client(base_url=server.url, timeout=30) as http,
    ):
        assert isinstance(server.process, subprocess.Popen)
        assert server.process.args[1:3] == ["-m", "service"]
        assert http.get("/healthz").json()["status"] == "ok"


def test_a_forked_command_is_the_command_s_run(tmp_path):
    """run_command forks python -m fitting: the same exit statuses, output streams and working directory."""
    argv = ["fit", "Au", "--eta-range", "1:2", "--no-metrics", "--json"]
    forked, spawned = (
        run_command("fitting", *argv),
        subprocess.run([sys.executable, "-m", "fitting", *argv], cwd=ROOT, capture_output=True, text=True, timeout=300),
    )
    assert forked.args == spawned.args and forked.returncode == spawned.returncode == 0
    views = [json.loads(result.stdout) for result in (forked, spawned)]
    for view in views:
        del view["fit"]["timings"]  # the seconds each step took: the only field two runs differ in
    assert views[0] == views[1] and forked.stderr == spawned.stderr
    refused = run_command("fitting", "fit", "Unobtainium")
    assert refused.returncode == 2 and refused.stdout == ""
    assert refused.stderr.startswith("error: `material` must name a conductor of the library")
    usage = run_command("fitting", "--no-such-option")
    assert usage.returncode == 2 and usage.stderr.startswith("usage: python -m fitting")
    (tmp_path / "metal.csv").write_text(
        "wavelength_nm,n,k\n350,0.4,2.0\n450,0.5,2.5\n550,0.55,2.8\n650,0.6,3.0\n750,0.7,3.8\n850,0.8,4.5\n"
    )
    # Relative paths are the working directory's. (The command itself needs the repository on PYTHONPATH
    # when run from elsewhere, an environment a fork cannot take; the fork has the package imported.)
    argv = ["fit", "--nk", "metal.csv", "--no-metrics", "-o"]
    forked = run_command("fitting", *argv, "forked.cfpk", cwd=tmp_path)
    spawned = subprocess.run(
        [sys.executable, "-m", "fitting", *argv, "spawned.cfpk"],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert forked.returncode == spawned.returncode == 0, forked.stderr + spawned.stderr
    assert (tmp_path / "forked.cfpk").read_bytes() == (tmp_path / "spawned.cfpk").read_bytes()


def test_a_forked_command_past_its_timeout_is_killed(tmp_path):
    started = time.monotonic()
    with pytest.raises(subprocess.TimeoutExpired):
        run_command("fitting", "reproduce", "-o", str(tmp_path / "results.md"), timeout=0.5)
    assert time.monotonic() - started < 30 and not (tmp_path / "results.md").exists()


def test_an_environment_a_fork_cannot_take_runs_the_command():
    from fitting.optics.catalogue import catalogue

    result = run_command("fitting", "library", env={**os.environ, "PYTHONHASHSEED": "7"})
    assert result.returncode == 0 and len(result.stdout.strip().splitlines()) == len(catalogue())
    with pytest.raises(ValueError, match="module must be one of service, fitting, preview_shaders"):
        SERVER_FORKS.run("benchmarks", ["--help"], dict(os.environ), ROOT)


@pytest.mark.parametrize("spawn", [False, True], ids=["forked", "command"])
def test_a_start_whose_port_was_taken_is_tried_again_on_another(tmp_path, monkeypatch, spawn):
    """A port taken between free_port() and the server's bind (another test's server; a CI run saw one)
    fails that start with "address already in use": the start is tried again on another port."""
    import conftest
    from ports import taken_first

    with taken_first(monkeypatch, conftest, "free_port") as (port, _):
        with server_process(tmp_path / "data", spawn=spawn) as server:
            assert server.port != port
            assert loopback.get(f"{server.url}/healthz", timeout=10).status_code == 200
            assert conftest.PORT_TAKEN in server.log_text()


def test_the_benchmark_s_start_is_tried_again_on_another_port(monkeypatch):
    """benchmarks/forked_servers.py's start: the same rule, for each side."""
    from ports import taken_first

    import benchmarks.forked_servers as forked

    forks = __import__("server_forks").ServerForks()
    try:
        for side in forked.SIDES:
            with taken_first(monkeypatch, forked, "free_port") as (_, first):
                run = forked.start(side, forks)
            assert run["ready_s"] > 0 and not first, (side, run)
            monkeypatch.undo()
    finally:
        forks.close()


def test_the_load_benchmarks_start_is_tried_again_on_another_port(tmp_path, monkeypatch):
    """benchmarks/serve.py's start_replicas (service_load, service_stores, export_downloads, preview_load and
    finite_inputs start their servers with it): a port taken first, the start is tried again."""
    from ports import taken_first

    import benchmarks.serve as serve

    with taken_first(monkeypatch, serve, "free_port") as (port, first):
        ((process, url),) = serve.start_replicas(1, dict(os.environ), str(tmp_path))
    try:
        assert not first and not url.endswith(f":{port}")
        assert loopback.get(f"{url}/healthz", timeout=10).status_code == 200
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
