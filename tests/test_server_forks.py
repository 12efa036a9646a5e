"""
tests/server_forks.py: the servers the tests fork from one interpreter
that has imported the service are ``python -m service`` in all but the
imports: their settings come from their environment, each leads a session
of its own with its output in its log, and their exit statuses are
``subprocess.Popen``'s; an environment a fork cannot take starts the
command itself.
"""

from __future__ import annotations

import os
import signal
import subprocess

import loopback
import pytest
from conftest import server_process
from server_forks import ForkedProcess, forkable

from benchmarks.server_start import stat_fields

pytestmark = [pytest.mark.server, pytest.mark.slow]

BASE = {"PATH": "/usr/bin", "HOME": "/root", "OPENBLAS_CORETYPE": "Haswell", "COATED_FIT_WORKERS": "1"}


@pytest.mark.parametrize("env, expected", [
    (BASE, True),
    ({**BASE, "COATED_FIT_WORKERS": "2", "COATED_FIT_QUEUE": "0"}, True),  # the service's settings
    ({**BASE, "TMPDIR": "/tmp/x"}, True),  # read when first used
    ({**BASE, "PYTEST_CURRENT_TEST": "tests/a.py::t (call)"}, True),
    ({k: v for k, v in BASE.items() if k != "COATED_FIT_WORKERS"}, True),
    ({**BASE, "OPENBLAS_CORETYPE": "Prescott"}, False),  # read by OpenBLAS when numpy is imported
    ({**BASE, "PYTHONHASHSEED": "1"}, False),  # read by the interpreter at its start
    ({k: v for k, v in BASE.items() if k != "PATH"}, False),
])
def test_a_fork_takes_only_the_service_s_variables(env, expected):
    assert forkable(BASE, env) is expected


def test_a_forked_server_reads_its_settings_leads_its_session_and_exits_as_the_command(tmp_path):
    with server_process(tmp_path / "data", COATED_FIT_WORKERS="3") as server, \
            loopback.Client(base_url=server.url, timeout=30) as http:
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
    with server_process(tmp_path / "data", PYTHONHASHSEED="7") as server, \
            loopback.Client(base_url=server.url, timeout=30) as http:
        assert isinstance(server.process, subprocess.Popen)
        assert server.process.args[1:3] == ["-m", "service"]
        assert http.get("/healthz").json()["status"] == "ok"
