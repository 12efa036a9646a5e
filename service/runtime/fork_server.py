"""
The fork server, forked from the server
=======================================

:func:`start_fork_server`: ``python -m service`` forks the fork server of
its fitting and render processes (:func:`service.runtime.worker.process_context`)
from itself, once it has imported the core and warmed up
(:mod:`service.runtime.preload`), before it opens the store or starts a thread;
multiprocessing's own fork server is a new interpreter that imports the
core and warms up again.

:func:`fork_server_exited`: a worker whose start failed with one of
:data:`START_ERRORS` asked a fork server that died, or is dying: waits
until its exit can be seen, so that multiprocessing starts another for the
next worker instead of asking the dying one again.
"""

from __future__ import annotations

import asyncio
import gc
import os
import socket
import sys
import threading
import time
from multiprocessing import connection, forkserver, resource_tracker, util

from .mp_private import FORK_SERVER_STATE, adopt_fork_server, fork_server, fork_server_pid
from .worker import end_with_parent

__all__ = ["START_ERRORS", "fork_server_exited", "start_fork_server"]


SUN_PATH_MAX = 107
"""The longest path of a Unix socket on Linux (``sun_path``'s 108 bytes with the final NUL)."""


def _cannot_fork_server(server, threads: int) -> str | None:
    """Why :func:`start_fork_server` starts nothing, given multiprocessing's ``ForkServer`` and the Python threads."""
    if set(vars(server)) != FORK_SERVER_STATE:
        return f"multiprocessing's ForkServer holds {sorted(vars(server))}, not {sorted(FORK_SERVER_STATE)}"
    if threads > 1:
        return f"{threads} Python threads run, and a fork would copy their locks mid-use"
    if fork_server_pid(server) is not None:
        return "a fork server runs already"
    return None


def start_fork_server() -> bool:
    """
    Start the fork server of :func:`service.runtime.worker.process_context` as a fork of this
    process, once it has imported :data:`service.runtime.worker.PRELOAD` (:mod:`service.runtime.preload`) (which also warms it up),
    instead of the new interpreter multiprocessing would start with the
    first pool, which imports the core and warms up again: a second of CPU
    time at every server start, and the first pool waits for it. For
    ``python -m service``, before the store is opened and before any
    thread: the fork server is then what multiprocessing's would be (one
    thread, the standard descriptors, the core imported), plus the
    server's own modules. It takes the place of the one multiprocessing
    starts: the listening socket in multiprocessing's temporary directory,
    the "alive" pipe whose end at all of this process's children tells it
    when to stop, and the loop (``multiprocessing.forkserver.main``). It
    is killed when this process dies, however it dies
    (:func:`service.worker.end_with_parent`), and so are its forks.

    Raises ``ValueError`` when the socket's path (in the temporary
    directory, ``TMPDIR``) is too long for a Unix socket, where
    multiprocessing's own fork server would fail later, with the first
    pool. Returns ``False``, starting nothing (multiprocessing starts its own with
    the first pool), when a fork server runs already, when this process has
    another Python thread (a fork would copy its locks mid-use), or when
    multiprocessing's ``ForkServer`` holds other state than the one set
    here (:data:`~service.runtime.mp_private.FORK_SERVER_STATE`; a Python that added to it, as 3.14
    adds an authentication key). Should the fork server die, multiprocessing
    starts its own at the next pool.
    """
    import service.runtime.preload  # noqa: F401 (the core, colour-science and the warm-up, for every fork)

    server = fork_server()
    if _cannot_fork_server(server, threading.active_count()) is not None:
        return False
    # No lock is held across the fork (there is no other thread to take one): a lock held there would stay
    # held in the fork server and in every process it forks.
    resource_tracker.ensure_running()
    with socket.socket(socket.AF_UNIX) as listener:
        address = connection.arbitrary_address("AF_UNIX")
        if len(os.fsencode(address)) > SUN_PATH_MAX:
            raise ValueError(
                f"the fork server's socket, {address}, is {len(os.fsencode(address))} bytes long; a Unix "
                f"socket's path has at most {SUN_PATH_MAX}: set TMPDIR to a shorter directory"
            )
        listener.bind(address)
        if not util.is_abstract_socket_namespace(address):
            os.chmod(address, 0o600)
        listener.listen()
        alive_r, alive_w = os.pipe()
        server_pid = os.getpid()
        try:
            pid = os.fork()
        except BaseException:
            os.close(alive_r)
            os.close(alive_w)
            raise
        if pid == 0:  # the fork server: serve forks until every holder of alive_w has exited
            code = 1
            try:
                os.close(alive_w)
                # Its workers hold the "alive" pipe too, so the pipe alone never ends it when
                # the server is killed: it dies with the server, and its forks with it.
                end_with_parent(server_pid)
                # What start-up made lives as long as the process: out of the collector's reach here and
                # in every fork (pages the collector would otherwise write to stay shared).
                gc.freeze()
                forkserver.main(listener.fileno(), alive_r, [])
            except SystemExit:  # main's way of stopping at the end of the "alive" pipe
                code = 0
            except BaseException:
                sys.excepthook(*sys.exc_info())
            finally:
                os._exit(code)
        os.close(alive_r)
    adopt_fork_server(address, alive_w, pid)
    return True


START_ERRORS = (EOFError, ConnectionError)
"""
What starting a worker raises (``ProcessPoolExecutor.submit``, which starts
the workers it lacks) when the fork server closed the request unanswered
(``EOFError``: "unexpected EOF", the pid never written) or cannot be
reached (a refused or reset connection, a broken pipe): it died, or it is
dying. A killed process's exit takes time (its memory is freed before its
descriptors are closed, longer on a loaded machine), and until it has
exited multiprocessing's check (``waitpid`` with ``WNOHANG``) finds it
alive and sends it the next start too.
"""

FORK_SERVER_EXIT_S = 5.0
"""How long :func:`fork_server_exited` waits for the fork server's exit to be seen."""


async def fork_server_exited(timeout_s: float | None = None, poll_s: float = 0.01) -> bool:
    """
    Wait (polling, at most ``timeout_s``, by default :data:`FORK_SERVER_EXIT_S`) until the fork server of
    :func:`service.runtime.worker.process_context` has exited, without reaping it:
    multiprocessing reaps it at the next start (``ForkServer.ensure_running``)
    and then starts a new one. For a start that failed with one of
    :data:`START_ERRORS`. Returns whether it exited (``True`` also when there
    is none, or it is not this process's child); ``False`` after
    ``timeout_s``, when it is alive after all, and the next start will tell.
    """
    pid = fork_server_pid()
    deadline = time.monotonic() + (FORK_SERVER_EXIT_S if timeout_s is None else timeout_s)
    while pid is not None:
        try:
            if os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None:
                return True
        except ChildProcessError:
            return True
        if time.monotonic() >= deadline:
            return False
        await asyncio.sleep(poll_s)
    return True
