"""
The one adapter to multiprocessing's private state (CPython 3.11-3.13): the
runtime reads and writes it here and nowhere else.

-   the fork server's state (``multiprocessing.forkserver._forkserver``):
    :func:`fork_server`, :func:`fork_server_pid`, :func:`adopt_fork_server`
    (:mod:`service.runtime.fork_server` puts its own fork server in the
    place of the one multiprocessing would start);
-   a ``ProcessPoolExecutor``'s worker processes and its result pipe:
    :func:`executor_processes`, :func:`close_result_pipe`
    (:mod:`service.runtime.executors` unsticks a pool whose worker died
    while it wrote a result).

:func:`mismatches` says, in words, what of this a running Python no longer
holds; ``tests/service/test_runtime_private.py`` fails on any, so a Python
release that changes them is seen at once, not as a pool that hangs.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
from multiprocessing import forkserver
from typing import Any

__all__ = [
    "FORK_SERVER_STATE",
    "adopt_fork_server",
    "close_result_pipe",
    "executor_processes",
    "fork_server",
    "fork_server_pid",
    "mismatches",
]

FORK_SERVER_STATE = frozenset(
    {
        "_forkserver_address",
        "_forkserver_alive_fd",
        "_forkserver_pid",
        "_inherited_fds",
        "_lock",
        "_preload_modules",
    }
)
"""The state of multiprocessing's ``ForkServer`` that :func:`adopt_fork_server` sets, as Python 3.11-3.13 hold it."""


def fork_server() -> Any:
    """multiprocessing's ``ForkServer`` of this process (the one every ``forkserver`` context uses)."""
    return forkserver._forkserver


def fork_server_pid(server: Any = None) -> int | None:
    """The pid of ``server``'s (by default this process's) fork server; ``None`` when none was started."""
    return (fork_server() if server is None else server)._forkserver_pid


def adopt_fork_server(address: str, alive_fd: int, pid: int) -> None:
    """Make the fork server listening at ``address`` (alive while ``alive_fd`` is open, ``pid``) multiprocessing's."""
    server = fork_server()
    with server._lock:
        server._forkserver_address = address
        server._forkserver_alive_fd = alive_fd
        server._forkserver_pid = pid


def executor_processes(executor: concurrent.futures.ProcessPoolExecutor) -> dict[int, Any]:
    """``executor``'s worker processes by pid; empty when shut down, before its first job, or on a Python that keeps them elsewhere."""
    return getattr(executor, "_processes", None) or {}


def close_result_pipe(executor: concurrent.futures.ProcessPoolExecutor) -> None:
    """Close this process's end of the pipe ``executor``'s workers send results on (its manager thread then reads end of file)."""
    queue = getattr(executor, "_result_queue", None)
    if queue is not None:
        queue._writer.close()


def mismatches() -> list[str]:
    """What of the private state used here this Python does not hold as expected (empty when all is as expected)."""
    found = []
    state = set(vars(forkserver.ForkServer()))
    if state != FORK_SERVER_STATE:
        found.append(f"multiprocessing's ForkServer holds {sorted(state)}, not {sorted(FORK_SERVER_STATE)}")
    if not isinstance(getattr(forkserver, "_forkserver", None), forkserver.ForkServer):
        found.append("multiprocessing.forkserver._forkserver is not the process's ForkServer")
    executor = concurrent.futures.ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("forkserver"))
    try:
        if not isinstance(getattr(executor, "_processes", None), dict):
            found.append("ProcessPoolExecutor._processes is not a dict of its worker processes")
        queue = getattr(executor, "_result_queue", None)
        if not hasattr(getattr(queue, "_writer", None), "close"):
            found.append("ProcessPoolExecutor._result_queue._writer is not a connection to close")
    finally:
        executor.shutdown(wait=False)
    return found
