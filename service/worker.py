"""
Fitting workers
===============

What runs in each worker process of :class:`service.pool.FitRunner`:

-   :func:`warm_process`: the start-up every worker (and the server process)
    does once, so that no request pays for imports and spectral weights.
-   :func:`worker_start`: a worker's initializer: one BLAS thread, the
    server's shared ring of cancelled job serials, the warm-up, then what
    the warm-up made frozen out of the garbage collector (:func:`freeze_heap`).
-   :func:`freeze_heap`, :func:`thaw_heap`: the process's objects so far
    moved out of the collector's reach, and back.
-   :func:`run_part`: one part of a job, checked every 0.1 s for its CPU
    time (:class:`JobCPULimit`) and for cancellation by the server.
-   :func:`process_context`: how the workers start (forks of a fork server),
    and :func:`start_fork_server`: that fork server forked from the
    server process at its start.
"""

from __future__ import annotations

import gc
import signal
import time
from typing import Any, Callable

__all__ = ["CANCEL_SLOTS", "JobCPULimit", "warm_process", "freeze_heap", "thaw_heap", "worker_start", "run_part",
           "ping", "process_context", "start_fork_server"]

CANCEL_SLOTS = 256
"""Cancelled job serials remembered (a ring); far more than jobs in flight."""

_CHECK_S = 0.1  # how often a worker checks its job's CPU time and cancellation
_cancelled = None  # in a worker: the server's shared ring of cancelled job serials


class JobCPULimit(ValueError):
    """A part of a job used more CPU time than its limit (raised in the worker, re-raised here; a 422)."""

    def __init__(self, limit_s: float) -> None:
        super().__init__(
            f"the job used more than its CPU-time limit of {limit_s:g} s (COATED_JOB_CPU_LIMIT_S) "
            "and was stopped; make the request smaller"
        )
        self.limit_s = limit_s

    def __reduce__(self):
        return JobCPULimit, (self.limit_s,)


class _Cancelled(Exception):
    """Raised in a worker whose job was cancelled by the server."""


class _OverLimit(BaseException):
    """
    Raised in a worker's job at its CPU-time limit, and turned into
    :class:`JobCPULimit` by :func:`run_part`. Not an ``Exception``: the
    check lands wherever the job is, and a ``ValueError`` there was caught
    by the job's own input checks (``except (TypeError, ValueError)`` around
    ``np.asarray`` in ``fitting.domain``) and answered as bad input.
    """


def warm_process() -> None:
    """
    Process start-up (each worker's initializer, and the server process at
    start-up, which computes curves and reference textures in threads):
    import the fitting core and colour-science and compute the spectral
    weights of the fit (5 nm) and of the metrics (1 nm) once, seconds that
    would otherwise land on the first request.
    """
    from fitting.colour.reference import spectral_weights
    from fitting.fits.settings import FitSettings

    spectral_weights(FitSettings().step_nm)
    spectral_weights(1.0)


def freeze_heap() -> None:
    """
    Move every object the process holds so far (its imports: colour-science,
    scipy, FastAPI, and the warm-up's caches) to the garbage collector's
    permanent generation (:func:`gc.freeze`), so that its full collections
    traverse only what requests made since. Measured before it
    (``benchmarks/live_overhead.py --gc-trace``): a full collection of the
    server process took 60-86 ms and of a worker 15-46 ms, and landed on
    about one live refit step in 160 (its round trip then 174-183 ms
    against a p99 of 76); the objects frozen are modules, functions and
    long-lived caches, which live as long as the process. Plain reference
    counting still frees a frozen object no longer referenced; only a cycle
    of them would wait for :func:`thaw_heap`.
    """
    gc.collect()  # what is already garbage is freed, not frozen
    gc.freeze()


def thaw_heap() -> None:
    """
    Undo :func:`freeze_heap` (:func:`gc.unfreeze`): the server's shutdown
    does, so that a process which starts and stops the service more than
    once (the tests' in-process clients) can collect what each left.
    """
    gc.unfreeze()


def worker_start(cancelled) -> None:
    """
    Each worker's initializer: the shared cancellation ring, the warm-up,
    then one BLAS thread for the process's life (after the warm-up: a limit
    applies only to the BLAS libraries already loaded).
    """
    global _cancelled
    from threadpoolctl import threadpool_limits

    _cancelled = cancelled
    warm_process()
    threadpool_limits(limits=1, user_api="blas")
    freeze_heap()


def run_part(serial: int, cpu_limit_s: float, function: Callable[..., Any], *args: Any) -> Any:
    """
    Worker: ``function(*args)`` with a check every 0.1 s (SIGALRM, in the
    worker's main thread, where the job runs) that stops it past
    ``cpu_limit_s`` of CPU time or once the server cancelled ``serial``.
    """
    cpu0 = time.process_time()

    def check(signum, frame) -> None:
        if _cancelled is not None and serial in _cancelled[:]:
            raise _Cancelled()
        if time.process_time() - cpu0 > cpu_limit_s:
            raise _OverLimit()

    previous = signal.signal(signal.SIGALRM, check)
    signal.setitimer(signal.ITIMER_REAL, _CHECK_S, _CHECK_S)
    try:
        try:
            return function(*args)
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, previous)
    except _OverLimit:  # in the job, or in an alarm that landed before the timer was off
        raise JobCPULimit(cpu_limit_s) from None


def ping() -> float:
    time.sleep(0.05)  # long enough that each warm-up ping lands on its own worker
    return time.time()


PRELOAD = ("service.preload",)
"""What the fork server imports once, so that each process forked from it starts with it (:mod:`service.preload`)."""


def process_context():
    """
    The start method of the fitting and render processes: ``forkserver``
    with :data:`PRELOAD`. The fork server is a single-threaded process (no
    GL context, no open connections of the server) that imported the
    fitting core and colour-science once; each worker is a fork of it.
    Forking the server itself would copy its threads' locks mid-use;
    spawning imports the core again in every worker. The service's entry
    point (``python -m service``) forks the fork server from itself before
    any thread starts (:func:`start_fork_server`); elsewhere (an application
    made in another program, the tests' in-process apps) multiprocessing
    starts it with the first pool, as a new interpreter that imports
    :data:`PRELOAD`, and again, that way, if it died. Measured by hand once
    (a pool of two workers, warm; not a recorded benchmark): the first pool
    1.5 s (that new fork server's imports), every pool after it, as after a
    worker died, 0.3 s, against 1.5-1.9 s each with ``spawn``. A process
    forked from it keeps the environment the fork server started with.
    """
    import multiprocessing

    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(list(PRELOAD))
    return context


_FORK_SERVER_STATE = frozenset({
    "_forkserver_address", "_forkserver_alive_fd", "_forkserver_pid", "_inherited_fds", "_lock", "_preload_modules",
})
"""The state of multiprocessing's ``ForkServer`` that :func:`start_fork_server` sets, as Python 3.11-3.13 hold it."""


def _cannot_fork_server(server, threads: int) -> str | None:
    """Why :func:`start_fork_server` starts nothing, given multiprocessing's ``ForkServer`` and the Python threads."""
    if set(vars(server)) != _FORK_SERVER_STATE:
        return f"multiprocessing's ForkServer holds {sorted(vars(server))}, not {sorted(_FORK_SERVER_STATE)}"
    if threads > 1:
        return f"{threads} Python threads run, and a fork would copy their locks mid-use"
    if server._forkserver_pid is not None:
        return "a fork server runs already"
    return None


def start_fork_server() -> bool:
    """
    Start the fork server of :func:`process_context` as a fork of this
    process, once it has imported :data:`PRELOAD` (which also warms it up),
    instead of the new interpreter multiprocessing would start with the
    first pool, which imports the core and warms up again: a second of CPU
    time at every server start, and the first pool waits for it. For
    ``python -m service``, before the store is opened and before any
    thread: the fork server is then what multiprocessing's would be (one
    thread, the standard descriptors, the core imported), plus the
    server's own modules. It takes the place of the one multiprocessing
    starts: the listening socket in multiprocessing's temporary directory,
    the "alive" pipe whose end at all of this process's children tells it
    when to stop, and the loop (``multiprocessing.forkserver.main``).

    Returns ``False``, starting nothing (multiprocessing starts its own with
    the first pool), when a fork server runs already, when this process has
    another Python thread (a fork would copy its locks mid-use), or when
    multiprocessing's ``ForkServer`` holds other state than the one set
    here (:data:`_FORK_SERVER_STATE`; a Python that added to it, as 3.14
    adds an authentication key). Should the fork server die, multiprocessing
    starts its own at the next pool.
    """
    import os
    import socket
    import sys
    import threading
    from multiprocessing import connection, forkserver, resource_tracker, util

    import service.preload  # noqa: F401 (the core, colour-science and the warm-up, for every fork)

    server = forkserver._forkserver
    if _cannot_fork_server(server, threading.active_count()) is not None:
        return False
    with server._lock:
        if server._forkserver_pid is not None:
            return False
        resource_tracker.ensure_running()
        with socket.socket(socket.AF_UNIX) as listener:
            address = connection.arbitrary_address("AF_UNIX")
            listener.bind(address)
            if not util.is_abstract_socket_namespace(address):
                os.chmod(address, 0o600)
            listener.listen()
            alive_r, alive_w = os.pipe()
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
        server._forkserver_address = address
        server._forkserver_alive_fd = alive_w
        server._forkserver_pid = pid
    return True
