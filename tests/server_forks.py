"""
Servers forked from one interpreter that has imported the service
=================================================================

A ``python -m service`` start spends most of its CPU time importing
(FastAPI and the route models, scipy.optimize, colour-science,
pydantic-settings: about 1.9 of its 2.4 CPU seconds, see
``benchmarks/server_start.py``), and the suite starts about forty servers.
:class:`ServerForks` starts, once a test process, one interpreter (this file
run as a program) that imports what ``python -m service`` imports and the
fork server's preload (:mod:`service.preload`, whose warm-up depends on no
setting), then forks a server for each :meth:`ServerForks.start`: the fork
sets the server's environment, working directory, session and output, and
returns to the top of this program, which runs
``sys.exit(service.__main__.main(argv))`` as ``python -m service`` does,
interpreter exit included. The server's code, sockets, store, fork server
and workers are those of ``python -m service``; only the imports are
shared.

The environment that an interpreter reads at its start (``PYTHON*``,
numpy's and OpenBLAS's kernels and threads) cannot change in a fork, so a
fork takes only a difference in the service's own variables (``COATED_*``),
``TMPDIR`` and pytest's ``PYTEST_CURRENT_TEST`` from the environment the
program started with (:func:`forkable`, :data:`FORK_MAY_SET`); tests/conftest.py's ``server_process`` starts
``python -m service`` itself for anything else, and where the command line
is what a test checks.

The program reaps its forks and keeps their exit statuses:
:class:`ForkedProcess` is ``subprocess.Popen``'s interface to one (``pid``,
``poll``, ``wait``, ``returncode``, ``send_signal``, ``terminate``, ``kill``)
over the program's standard input and output, one JSON line a request. It
exits when its standard input closes (the test process ended) and leaves
the servers to their stops, as a ``Popen``'s would be.
"""

from __future__ import annotations

import gc
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

FORK_MAY_SET = ("COATED_", "TMPDIR", "PYTEST_CURRENT_TEST")
"""
What a fork may set differently from the program's environment (names
starting so): the service's settings, the temporary directory (read when
first used) and pytest's name of the running test.
"""

def forkable(base: dict[str, str], env: dict[str, str]) -> bool:
    """Whether a server with environment ``env`` can be forked from a program started with ``base``."""
    changed = {key for key in base.keys() | env.keys() if base.get(key) != env.get(key)}
    return all(key.startswith(FORK_MAY_SET) for key in changed)


class ForkedProcess:
    """A forked server: ``subprocess.Popen``'s interface, answered by the program that forked it."""

    def __init__(self, forks: ServerForks, pid: int) -> None:
        self._forks = forks
        self.pid = pid
        self.returncode: int | None = None

    def poll(self) -> int | None:
        if self.returncode is None:
            self.returncode = self._forks.request(op="wait", pid=self.pid, timeout_s=0.0)["returncode"]
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        """The exit status (``-signal`` if a signal ended it); ``subprocess.TimeoutExpired`` after ``timeout`` s."""
        if self.returncode is None:
            answer = self._forks.request(op="wait", pid=self.pid, timeout_s=timeout)
            if answer["returncode"] is None:
                raise subprocess.TimeoutExpired(f"server {self.pid}", timeout)
            self.returncode = answer["returncode"]
        return self.returncode

    def send_signal(self, signum: int) -> None:
        if self.poll() is None:  # not to another process that took its pid
            os.kill(self.pid, signum)

    def terminate(self) -> None:
        self.send_signal(signal.SIGTERM)

    def kill(self) -> None:
        self.send_signal(signal.SIGKILL)


class ServerForks:
    """The program of this file, started on the first :meth:`start` and stopped by :meth:`close`."""

    def __init__(self) -> None:
        self.program: subprocess.Popen | None = None
        self.environment: dict[str, str] = {}
        self._lock = threading.Lock()  # one request at a time on the program's pipes

    def running(self) -> bool:
        return self.program is not None and self.program.poll() is None

    def can_fork(self, env: dict[str, str]) -> bool:
        """Whether :meth:`start` takes ``env``: :func:`forkable` from the program's environment (to be: this one's)."""
        return forkable(self.environment if self.running() else dict(os.environ), env)

    def start(self, argv: list[str], env: dict[str, str], log: Path) -> ForkedProcess:
        """
        Fork ``python -m service ARGV`` with environment ``env`` (``forkable``
        from this process's), in its own session, its output appended to
        ``log``.
        """
        if not self.can_fork(env):
            raise ValueError(f"env differs from the program's environment in more than {FORK_MAY_SET}")
        if not self.running():
            self.environment = dict(os.environ)
            self.program = subprocess.Popen(
                [sys.executable, "-c", "import runpy; runpy.run_path('tests/server_forks.py', run_name='__main__')"],
                cwd=ROOT, env=self.environment, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
            )
            self.request(op="ready")
        answer = self.request(op="start", argv=argv, env=env, log=str(log), cwd=str(ROOT))
        return ForkedProcess(self, answer["pid"])

    def request(self, **message) -> dict:
        with self._lock:
            self.program.stdin.write(json.dumps(message) + "\n")
            self.program.stdin.flush()
            line = self.program.stdout.readline()
        if not line:
            raise RuntimeError(f"tests/server_forks.py exited with {self.program.wait()} (its errors: stderr)")
        return json.loads(line)

    def close(self) -> None:
        if self.program is not None:
            self.program.stdin.close()
            self.program.wait(timeout=30)
            self.program.stdout.close()
            self.program = None


# -- the program ---------------------------------------------------------------

def _returncode(status: int) -> int:
    return -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)


def _serve_requests() -> list[str] | None:
    """
    Answer requests until standard input closes (``None``); in a fork, the
    server's ``argv``, its process set up as ``subprocess.Popen`` with
    ``start_new_session`` would have set it up.
    """
    exited: dict[int, int] = {}

    def reap() -> None:
        while True:
            try:
                pid, status = os.waitpid(-1, os.WNOHANG)
            except ChildProcessError:
                return
            if pid == 0:
                return
            exited[pid] = _returncode(status)

    def answer(message: dict) -> None:
        sys.stdout.write(json.dumps(message) + "\n")
        sys.stdout.flush()

    for line in sys.stdin:
        request = json.loads(line)
        if request["op"] == "ready":
            answer({})
        elif request["op"] == "wait":
            deadline = None if request["timeout_s"] is None else time.monotonic() + request["timeout_s"]
            reap()
            while request["pid"] not in exited and (deadline is None or time.monotonic() < deadline):
                time.sleep(0.01)
                reap()
            answer({"returncode": exited.get(request["pid"])})
        elif request["op"] == "start":
            pid = os.fork()
            if pid == 0:
                try:
                    _become_server(request)
                except BaseException:  # not on to the program's loop in a fork
                    sys.excepthook(*sys.exc_info())
                    os._exit(1)
                return request["argv"]
            answer({"pid": pid})
        else:
            raise ValueError(f"unknown request {request['op']!r}")
    return None


def _become_server(request: dict) -> None:
    os.setsid()
    log = os.open(request["log"], os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    os.dup2(log, 1)
    os.dup2(log, 2)
    os.close(null)
    os.close(log)
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    tempfile.tempdir = None  # read again from TMPDIR
    # The signal handlers are an interpreter's at its start: the program sets none.


if __name__ == "__main__":
    sys.path[0] = os.getcwd()  # as ``python -m``'s (``-c`` puts '' there)
    import service.__main__
    import service.preload  # noqa: F401 (the fork server's imports and warm-up, as start_fork_server has them)

    # What the imports made lives as long as every fork: out of the collector's reach now, as each server's
    # start would put it (service.worker.freeze_heap), which then collects only what that server made.
    gc.collect()
    gc.freeze()
    argv = _serve_requests()
    if argv is None:
        sys.exit(0)
    sys.argv = [service.__main__.__file__, *argv]
    sys.exit(service.__main__.main(argv))
