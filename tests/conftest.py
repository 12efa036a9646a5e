"""
Shared fixtures of the test suite.

-   ``client``: a ``fastapi.testclient.TestClient`` over
    ``service.main.create_app`` with a fresh data directory (``tmp_path``),
    the lifespan run (store open, fitting pool made on the first fit), one
    fit worker, metrics on a 30 x 30 grid (fast; the service default is the
    paper's 100 x 100). Use it as ``client.post("/api/v1/fits", json=...)``.
-   ``live_server``: a real ``python -m service --port <free port>`` process
    on 127.0.0.1 with a fresh data directory; waits for ``/healthz`` and
    yields the base URL (``"http://127.0.0.1:<port>"``); terminates the
    process afterwards. Mark tests that use it ``@pytest.mark.server``.
    Servers are forked from one interpreter that has imported the service
    (tests/server_forks.py: the imports are most of a start's CPU time)
    where their environment differs from its own only in the service's
    ``COATED_*``, ``TMPDIR`` and ``PYTEST_CURRENT_TEST``
    (``server_forks.FORK_MAY_SET``); else, and with
    ``server_process(..., spawn=True)``, the command itself starts.
-   :func:`run_command`: ``python -m fitting ...`` (or another package) as
    ``subprocess.run(..., capture_output=True, text=True)`` runs it, forked
    from the same program where the environment allows.
-   :func:`app_client`: the TestClient factory behind ``client``, with
    settings overrides (``with app_client(tmp_path, fit_queue=0) as c: ...``).
-   ``reader``: one such app for all the tests of a module that only read
    or are refused (nothing stored, the store left open).
-   :func:`server_process`: the context manager behind ``live_server``, for
    tests that need their own data directory, environment or a restart
    (``with server_process(data_dir, COATED_FIT_QUEUE="0") as server: ...``;
    ``server.url``, ``server.process``, ``server.kill()``).
-   ``postgres_server``: one throwaway PostgreSQL server for the session
    (:class:`postgres_server.PostgresServer`: temporary directory, free
    loopback port, run as the ``postgres`` user when the tests run as
    root); ``postgres_url``: a fresh empty database on it per test. Tests
    that use them belong to ``@pytest.mark.xdist_group("postgres")`` (one
    worker under ``--dist loadgroup``; under ``scripts/test``'s ``--dist
    loadscope`` each pytest-xdist worker that runs one starts its own server).

The ``slow`` marker (``scripts/test --quick`` leaves those tests out) is on
every test that starts a process, a GL context or a browser, or that took
over 2 s in a ``--durations=0`` run. The ``gl``, ``server`` and ``browser``
markers imply it. What cannot be forgotten is checked: a test not marked
``slow`` that starts a process (``subprocess``, ``multiprocessing``: a CLI,
a server, the fitting pool, Chromium, Blender, Dask) or a GL context fails
with a message saying so (a start on the main thread or on a thread made
during the test; threads left by earlier tests, such as a module's server
or pool, are not the test's). A run lists, at its end, the tests not marked
``slow`` that took over 2 s.
"""

from __future__ import annotations

import contextlib
import functools
import multiprocessing.process
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Iterator

import httpx
import loopback
import moderngl
import pytest
from server_forks import ServerForks

ROOT = Path(__file__).resolve().parents[1]

SERVER_START_TIMEOUT_S = 120.0


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


SERVER_FORKS = ServerForks()
"""This test process's program that forks servers (tests/server_forks.py), started on first use."""

PORT_TAKEN = "address already in use"
"""What a server's log says when its port was taken between free_port() and its bind."""

PORT_TRIES = 3


class ServerProcess:
    """
    A running ``python -m service``: its URL, process and data directory.
    Forked from :data:`SERVER_FORKS` where the environment allows
    (``ServerForks.can_fork``) unless ``spawn``; else started as the
    command itself. Either way in a session of its own, its output in ``log``.
    """

    def __init__(self, data_dir: Path, env: dict[str, str], log: Path, spawn: bool = False) -> None:
        self.data_dir = data_dir
        self.log = log
        self._log_file = open(log, "ab")
        self._env = {**os.environ, **env}
        self._spawn = spawn
        self._start()

    def _start(self) -> None:
        """Start the server on a free port (its output appended to the log)."""
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self._log_start = self.log.stat().st_size if self.log.exists() else 0
        argv = ["--host", "127.0.0.1", "--port", str(self.port), "--data-dir", str(self.data_dir)]
        if not self._spawn and SERVER_FORKS.can_fork(self._env):
            self.process = SERVER_FORKS.start(argv, self._env, self.log)
        else:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "service", *argv],
                cwd=ROOT,
                env=self._env,
                stdout=self._log_file,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

    def _port_taken(self) -> bool:
        """Whether this start's output says its port was taken between free_port() and its bind."""
        self._log_file.flush()
        with open(self.log, "rb") as log:
            log.seek(self._log_start)
            return PORT_TAKEN in log.read().decode(errors="replace")

    def wait_ready(self, timeout_s: float = SERVER_START_TIMEOUT_S) -> None:
        deadline = time.monotonic() + timeout_s
        tries = 1
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                # Another test's server (or any program) can take the port between free_port() and the
                # bind: that start is tried again on another port, twice at most.
                if tries < PORT_TRIES and self._port_taken():
                    tries += 1
                    self._start()
                    continue
                raise RuntimeError(f"the server exited with {self.process.returncode}:\n{self.log_text()}")
            try:
                if loopback.get(f"{self.url}/healthz", timeout=2.0).status_code == 200:
                    return
            except httpx.TransportError:
                pass
            time.sleep(0.05)
        raise RuntimeError(f"the server did not answer /healthz in {timeout_s} s:\n{self.log_text()}")

    def log_text(self) -> str:
        self._log_file.flush()
        return self.log.read_text(errors="replace")[-4000:]

    def kill(self) -> None:
        """SIGKILL the server and its worker processes (its own session)."""
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.process.pid, signal.SIGKILL)
        self.process.wait(timeout=30)

    def stop(self) -> None:
        """SIGTERM (graceful shutdown), SIGKILL after 30 s."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.kill()
        # Worker processes left behind by a kill share the session; end them too.
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(self.process.pid, signal.SIGKILL)
        self._log_file.close()


@contextlib.contextmanager
def server_process(data_dir: Path, spawn: bool = False, **env: str) -> Iterator[ServerProcess]:
    """
    Start ``python -m service`` on a free loopback port (forked, or with
    ``spawn`` the command itself: :class:`ServerProcess`); stop it on exit.
    """
    env = {"COATED_FIT_WORKERS": "1", "COATED_METRICS_SAMPLES": "30", **env}
    server = ServerProcess(Path(data_dir), env, Path(data_dir).with_suffix(".log"), spawn)
    try:
        server.wait_ready()
        yield server
    finally:
        server.stop()


def run_command(
    module: str, *args: str, cwd: Path = ROOT, timeout: float | None = 300, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess:
    """
    ``python -m MODULE ARGS`` (``fitting``, ``service`` or ``preview_shaders``) as ``subprocess.run``
    with ``capture_output=True, text=True`` runs it: forked from
    :data:`SERVER_FORKS` where ``env`` (default this process's) allows
    (``ServerForks.can_fork``), else the command itself.
    """
    env = dict(os.environ) if env is None else env
    if SERVER_FORKS.can_fork(env):
        return SERVER_FORKS.run(module, list(args), env, cwd, timeout)
    return subprocess.run(
        [sys.executable, "-m", module, *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout
    )


def app_client(tmp_path: Path, **overrides):
    """
    A TestClient over an app with its own data directory under ``tmp_path``,
    one fit worker, no pool warm-up, no heap freeze (the heap is the test
    process's: each start would collect all of it), and ``overrides`` of
    :class:`service.config.Settings` (use it as a context manager).
    """
    from fastapi.testclient import TestClient

    from service.config import Settings
    from service.main import create_app

    # TestClient sends `Host: testserver`; it is allowed here as a deployment would name its host.
    options = {
        "data_dir": tmp_path / "data",
        "fit_workers": 1,
        "warm_pool": False,
        "freeze_heap": False,
        "allowed_hosts": ["localhost", "127.0.0.1", "::1", "testserver"],
        **overrides,
    }
    return TestClient(create_app(Settings(**options)))


SHOWROOM_SCENE = {
    "name": "showroom",
    "materials": [
        {"material": "Au", "eta_i": 1.0},
        {"material": "Cu", "eta_i": [1.5, 1.33]},
        {"material": "Al", "eta_i": {"min": 1.3, "max": 1.6}},
        {"material": "Cr", "name": "trim", "eta_i": 2.8},
    ],
}
"""One scene of every kind of eta_i specification (one value, a set, a range, a high one)."""


@pytest.fixture(scope="session")
def showroom():
    """:data:`SHOWROOM_SCENE` fitted (``fitting.fits.scene_fit.fit_scene``), once a session."""
    from fitting.fits.scene_fit import fit_scene
    from fitting.fits.scene_schema import parse_scene

    return fit_scene(parse_scene(SHOWROOM_SCENE))


@pytest.fixture(scope="session")
def postgres_server():
    from postgres_server import PostgresServer

    server = PostgresServer()
    try:
        yield server
    finally:
        server.close()


@pytest.fixture
def postgres_url(postgres_server) -> str:
    return postgres_server.database()


@pytest.fixture
def client(tmp_path):
    with app_client(tmp_path, metrics_samples=30) as test_client:
        yield test_client


@pytest.fixture(scope="module")
def reader(tmp_path_factory):
    """
    ``client``'s app shared by a module's tests that only read or are
    refused (a 404, 413 or 422: nothing they send is stored, and none closes
    the store): an app's first request costs about 0.3 s of CPU (FastAPI
    builds its routes' models then), more than most such tests.
    """
    with app_client(tmp_path_factory.mktemp("reader"), metrics_samples=30) as test_client:
        yield test_client


@pytest.fixture
def live_server(tmp_path) -> Iterator[str]:
    with server_process(tmp_path / "data") as server:
        yield server.url


@pytest.fixture(scope="session")
def browser_server(tmp_path_factory) -> Iterator[ServerProcess]:
    """
    One server process with the defaults for the browser modules of a test
    process (each pytest-xdist worker: its own), started by the first of
    them and stopped at the end of the session: a start is seconds of CPU
    (the server, its fork server and workers import the core), and the
    modules, which already shared one a module, assume nothing of the store
    but what they make (tests/static/editor_pages.py).
    """
    with server_process(tmp_path_factory.mktemp("browser") / "data") as server:
        yield server


# -- the slow marker ---------------------------------------------------------

SLOW_S = 2.0
"""A test taking longer than this (setup, call and teardown) is ``slow``."""

_IMPLY_SLOW = ("gl", "server", "browser")
PROCESS_FIXTURES = frozenset(
    {
        "shared",
        "fitted",
        "live_server",
        "browser_server",
        "editor_url",
        "pages",
        "page",
        "curve_fit",
        "rgb_fit",
        "hostile_run",
        "chromium",
        "postgres_server",
        "postgres_url",
    }
)
"""
Fixtures (by name, in any module) that start a process: the fitting pool's
workers on their first fit, a server, Chromium. A test using one, directly
or through another fixture, is ``slow``. The list is measured: a fixture
not in it that starts a process fails the test that set it up, naming it.
"""
_started: list[str] = []  # what the running test started
_fixture_started: dict[str, list[str]] = {}  # fixture name -> what its set-up started
_unmarked_slow: list[tuple[float, str]] = []


_old_threads: set[int] = set()  # threads of earlier tests (their servers, pools): not this test's


def _watch(what: str, function):
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        if threading.get_ident() not in _old_threads:
            _started.append(what)
        return function(*args, **kwargs)

    return wrapper


subprocess.Popen.__init__ = _watch("a process (subprocess)", subprocess.Popen.__init__)
multiprocessing.process.BaseProcess.start = _watch(
    "a process (multiprocessing)", multiprocessing.process.BaseProcess.start
)
moderngl.create_context = _watch("a GL context", moderngl.create_context)
ServerForks.start = _watch("a process (a server forked by tests/server_forks.py)", ServerForks.start)
ServerForks.run = _watch("a process (a command forked by tests/server_forks.py)", ServerForks.run)


def _first_rank(item) -> int:
    """Browser modules first, then server ones, then the rest (see pytest_collection_modifyitems)."""
    if item.get_closest_marker("browser"):
        return 0
    return 1 if item.get_closest_marker("server") else 2


def pytest_configure(config):
    """
    One BLAS thread in each test process: pytest-xdist runs a process a core,
    and OpenBLAS's own threads (as many as cores, spinning between calls)
    only took CPU from the other worker (the float32 reference's tests used
    a fifth more CPU time with them). Processes the tests start are not
    affected (a limit is the process's own).
    """
    import numpy  # noqa: F401 (a limit applies to the BLAS libraries loaded: numpy's and scipy's)
    import scipy.linalg  # noqa: F401
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")


def pytest_unconfigure(config):
    SERVER_FORKS.close()


def pytest_collection_modifyitems(config, items):
    for item in items:
        if any(item.get_closest_marker(name) for name in _IMPLY_SLOW) or PROCESS_FIXTURES.intersection(
            item.fixturenames
        ):
            item.add_marker(pytest.mark.slow)
    # The longest modules first: pytest-xdist hands out modules in this order,
    # so a long browser module collected last (tests/static/) would run on one
    # worker after the other has finished. A stable sort by each module's
    # rank keeps every module's tests together and in their order.
    rank: dict[str, int] = {}
    for item in items:
        rank[item.module.__name__] = min(rank.get(item.module.__name__, 2), _first_rank(item))
    items.sort(key=lambda item: rank[item.module.__name__])


@pytest.hookimpl(hookwrapper=True)
def pytest_fixture_setup(fixturedef, request):
    before = len(_started)
    yield
    if len(_started) > before:
        _fixture_started[fixturedef.argname] = _started[before:]


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    _started.clear()
    _old_threads.clear()
    _old_threads.update(t.ident for t in threading.enumerate() if t is not threading.main_thread())
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_teardown(item, nextitem):
    """After a test's fixtures are torn down: the browser modules' Chromium closes unless the next test uses it."""
    yield
    editor_pages = sys.modules.get("editor_pages")  # tests/static/editor_pages.py, once a browser module is imported
    if editor_pages is not None:
        editor_pages.release_chromium(nextitem)


_durations: dict[str, float] = {}
_module_s: dict[str, float] = {}  # test module -> seconds of its tests (setup, call, teardown)
_worker_s: dict[str, float] = {}  # pytest-xdist worker -> seconds of the tests it ran


def pytest_runtest_logreport(report):
    """
    The tests not marked slow that took over SLOW_S (here, and in the
    controller under xdist); each module's and each worker's seconds.
    """
    _durations[report.nodeid] = _durations.get(report.nodeid, 0.0) + report.duration
    module = report.nodeid.split("::", 1)[0]
    _module_s[module] = _module_s.get(module, 0.0) + report.duration
    worker = getattr(getattr(report, "node", None), "gateway", None)
    if worker is not None:
        _worker_s[worker.id] = _worker_s.get(worker.id, 0.0) + report.duration
    if report.when == "teardown":
        seconds = _durations.pop(report.nodeid, 0.0)
        if "slow" not in report.keywords and seconds > SLOW_S:
            _unmarked_slow.append((seconds, report.nodeid))


_STARTED = pytest.StashKey[list]()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if call.when == "call":
        # What the test's set-up and call started; a teardown may end a
        # module's fixtures, whose processes belong to the tests that used them.
        item.stash[_STARTED] = list(_started)
    if (
        call.when == "teardown"
        and item.stash.get(_STARTED, None)
        and item.get_closest_marker("slow") is None
        and report.passed
    ):
        fixtures = sorted(name for name in item.fixturenames if name in _fixture_started)
        where = (
            f" in the set-up of the fixture(s) {', '.join(fixtures)} (add them to tests/conftest.py's PROCESS_FIXTURES)"
            if fixtures
            else ""
        )
        report.outcome = "failed"
        report.longrepr = (
            f"{item.nodeid} started {', '.join(sorted(set(item.stash[_STARTED])))}{where} but is not "
            "marked `slow` (@pytest.mark.slow): scripts/test --quick must start no process, "
            "GL context or browser"
        )


def pytest_terminal_summary(terminalreporter, config):
    """With ``--durations``: the slowest modules (their tests' seconds summed) and each worker's seconds."""
    if config.option.durations is not None and _module_s:
        count = config.option.durations or len(_module_s)
        terminalreporter.write_sep("=", f"slowest {min(count, len(_module_s))} modules (seconds of their tests)")
        for module, seconds in sorted(_module_s.items(), key=lambda item: -item[1])[:count]:
            terminalreporter.write_line(f"{seconds:7.1f}s {module}")
        for worker, seconds in sorted(_worker_s.items()):
            terminalreporter.write_line(f"{seconds:7.1f}s of tests on {worker}")
    if _unmarked_slow:
        terminalreporter.write_sep("-", f"not marked slow, over {SLOW_S:g} s")
        for seconds, nodeid in sorted(_unmarked_slow, reverse=True):
            terminalreporter.write_line(f"{seconds:6.2f}s {nodeid}")
