"""
Servers and commands forked from one interpreter that has imported them
=======================================================================

A ``python -m service`` start spends most of its CPU time importing
(FastAPI and the route models, scipy.optimize, colour-science,
pydantic-settings: about 1.9 of its 2.4 CPU seconds, see
``benchmarks/server_start.py``), and the suite starts about forty servers;
a ``python -m fitting`` command spends about 0.65 of its 0.9 CPU seconds
importing the core, and the suite runs about thirty (and four of
``python -m preview_shaders``).
:class:`ServerForks` starts, once a test process, one interpreter (this file
run as a program) that imports what ``python -m service``,
``python -m fitting`` and ``python -m preview_shaders`` import (no GL
context: each command makes its own) and the fork server's preload
(:mod:`service.runtime.preload`, whose warm-up depends on no setting), then forks
a server for each :meth:`ServerForks.start` and a command for each
:meth:`ServerForks.run`: the fork sets the process's environment, working
directory, output (and a server's session), and returns to the top of this
program, which runs the package's ``__main__`` module as ``python -m``
does (:func:`runpy.run_module` and ``sys.argv``), and exits as the
interpreter does but for the tear-down of the modules' objects
(:func:`_exit`). The server's code, sockets, store, fork server and workers, and
the command's, are those of ``python -m``; only the imports are shared.

The environment that an interpreter reads at its start (``PYTHON*``,
numpy's and OpenBLAS's kernels and threads) cannot change in a fork, so a
fork takes only a difference in the service's own variables (``COATED_*``),
``TMPDIR`` and pytest's ``PYTEST_CURRENT_TEST`` from the environment the
program started with (:func:`forkable`, :data:`FORK_MAY_SET`); tests/conftest.py's ``server_process``
and ``run_command`` start the command itself for anything else, and where
the command line is what a test checks.

The program reaps its forks and keeps their exit statuses:
:class:`ForkedProcess` is ``subprocess.Popen``'s interface to one (``pid``,
``poll``, ``wait``, ``returncode``, ``send_signal``, ``terminate``, ``kill``)
over the program's standard input and output, one JSON line a request. It
exits when its standard input closes (the test process ended) and leaves
the servers to their stops, as a ``Popen``'s would be.
"""

from __future__ import annotations

import atexit
import gc
import json
import os
import runpy
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PROGRAMS = ("service", "fitting", "preview_shaders")
"""The packages whose ``python -m`` the program forks (it imports what each imports)."""

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
        return self._fork(
            module="service",
            argv=argv,
            env=env,
            cwd=str(ROOT),
            stdout=str(log),
            stderr=str(log),
            append=True,
            session=True,
        )

    def run(
        self,
        module: str,
        argv: list[str],
        env: dict[str, str],
        cwd: Path,
        timeout: float | None = None,
    ) -> subprocess.CompletedProcess:
        """
        ``subprocess.run([sys.executable, "-m", module, *argv], cwd=cwd,
        env=env, capture_output=True, text=True, timeout=timeout)`` for
        ``module`` one of :data:`PROGRAMS`, forked (``env`` ``forkable``
        from this process's): standard input ``/dev/null``, the output
        captured in files and returned as text; on ``timeout`` the process is
        killed and ``subprocess.TimeoutExpired`` raised, as ``subprocess.run``
        does.
        """
        with tempfile.TemporaryDirectory(prefix="server-forks-run-") as directory:
            out, err = Path(directory) / "stdout", Path(directory) / "stderr"
            process = self._fork(
                module=module,
                argv=list(argv),
                env=env,
                cwd=str(cwd),
                stdout=str(out),
                stderr=str(err),
                append=False,
                session=False,
            )
            try:
                returncode = process.wait(timeout)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
                raise
            return subprocess.CompletedProcess(
                [sys.executable, "-m", module, *argv], returncode, out.read_text(), err.read_text()
            )

    def _fork(self, **request) -> ForkedProcess:
        if request["module"] not in PROGRAMS:
            raise ValueError(f"module must be one of {', '.join(PROGRAMS)}, got {request['module']!r}")
        if not self.can_fork(request["env"]):
            raise ValueError(f"env differs from the program's environment in more than {FORK_MAY_SET}")
        if not self.running():
            self.environment = dict(os.environ)
            self.program = subprocess.Popen(
                [sys.executable, "-c", "import runpy; runpy.run_path('tests/server_forks.py', run_name='__main__')"],
                cwd=ROOT,
                env=self.environment,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                text=True,
            )
            self.request(op="ready")
        answer = self.request(op="start", **request)
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


def _serve_requests() -> tuple[str, list[str]] | None:
    """
    Answer requests until standard input closes (``None``); in a fork, the
    ``(module, argv)`` it is to run, its process set up as ``subprocess.Popen``
    would have set it up (a server's with ``start_new_session``).
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
                    _become(request)
                except BaseException:  # not on to the program's loop in a fork
                    sys.excepthook(*sys.exc_info())
                    os._exit(1)
                return request["module"], request["argv"]
            answer({"pid": pid})
        else:
            raise ValueError(f"unknown request {request['op']!r}")
    return None


def _become(request: dict) -> None:
    if request["session"]:
        os.setsid()
    flags = os.O_WRONLY | os.O_CREAT | (os.O_APPEND if request["append"] else os.O_TRUNC)
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    os.close(null)
    for fd, path in ((1, request["stdout"]), (2, request["stderr"])):
        target = os.open(path, flags, 0o644)
        os.dup2(target, fd)
        os.close(target)
    os.chdir(request["cwd"])
    sys.path[0] = os.getcwd()  # python -m's first entry: its working directory
    os.environ.clear()
    os.environ.update(request["env"])
    tempfile.tempdir = None  # read again from TMPDIR
    # The signal handlers are an interpreter's at its start: the program sets none.


def _exit(main) -> None:
    """
    Run ``main`` and exit as the interpreter does after ``python -m``: the
    status of its ``SystemExit`` (0 if it returned; 1 and the traceback
    after another exception), the non-daemon threads joined, the ``atexit``
    handlers run (multiprocessing's clean-up among them) and the standard
    streams flushed, then ``os._exit``. The interpreter's tear-down of the
    modules' objects is left out: in a fork it writes to the pages of the
    heap shared with the program (copying each): a server's stop took
    2.2 s instead of 0.3 s at a load of 13, about 0.4 s more on a quiet
    machine, the process on the CPU all along.
    """
    try:
        main()
        status = 0
    except SystemExit as stop:
        status = _exit_status(stop.code)
    except BaseException:
        sys.excepthook(*sys.exc_info())
        status = 1
    threading._shutdown()  # what the interpreter's exit calls first: wait for the non-daemon threads
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(status)


def _exit_status(code) -> int:
    """A ``SystemExit``'s code as the interpreter's status: ``None`` 0, an int itself, else printed and 1."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code & 0xFF
    print(code, file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.path[0] = os.getcwd()  # as ``python -m``'s (``-c`` puts '' there)
    import fitting.cli.main  # noqa: F401 (what python -m fitting imports)
    import preview_shaders.display  # noqa: F401 (what python -m preview_shaders imports; no GL context here)
    import preview_shaders.preview  # noqa: F401

    # What python -m service imports, at its start and then in main (not service.__main__ itself, which
    # run_module executes as __main__, as -m does).
    import service.runtime.fork_server  # noqa: F401
    import service.main  # noqa: F401
    import service.runtime.preload  # noqa: F401 (the fork server's imports and warm-up, as start_fork_server has them)
    import service.runtime.server  # noqa: F401

    # What the imports made lives as long as every fork: out of the collector's reach now, as each server's
    # start would put it (service.runtime.worker.freeze_heap), which then collects only what that server made.
    gc.collect()
    gc.freeze()
    started = _serve_requests()
    if started is None:
        sys.exit(0)
    module, sys.argv = started[0], ["-m", *started[1]]  # run_module puts the __main__ file's path first
    _exit(lambda: runpy.run_module(module, run_name="__main__", alter_sys=True))
