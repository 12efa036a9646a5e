"""
Fitting workers
===============

What runs in each worker process of :class:`service.runtime.pool.FitRunner`:

-   :func:`warm_process`: the start-up every worker (and the server process)
    does once, so that no request pays for imports and spectral weights.
-   :func:`worker_start`: a worker's initializer: it ends with the server
    (:func:`end_with_parent`), one BLAS thread, the server's shared ring of
    cancelled job serials, the warm-up, then what the warm-up made frozen
    out of the garbage collector (:func:`freeze_heap`).
-   :func:`end_with_parent`: the process is killed when its parent dies,
    however it dies (Linux's parent-death signal).
-   :func:`freeze_heap`, :func:`thaw_heap`: the process's objects so far
    moved out of the collector's reach, and back.
-   :func:`run_part`: one part of a job, checked every 0.1 s for its CPU
    time (:class:`JobCPULimit`) and for cancellation by the server.
-   :func:`process_context`: how the workers start (forks of a fork server;
    :mod:`service.runtime.fork_server` forks it from the server process).
"""

from __future__ import annotations

import ctypes
import gc
import multiprocessing
import os
import signal
import threading
import time
from multiprocessing.connection import wait
from typing import Any, Callable

__all__ = [
    "CANCEL_SLOTS",
    "JobCPULimit",
    "warm_process",
    "freeze_heap",
    "thaw_heap",
    "worker_start",
    "run_part",
    "ping",
    "process_context",
    "end_with_parent",
]

_PR_SET_PDEATHSIG = 1  # prctl(2) option, <linux/prctl.h>

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


def end_with_parent(parent_pid: int | None = None) -> None:
    """
    End this process when its parent dies, however it dies (a SIGKILL of
    the server runs none of its exit code):

    -   the kernel SIGKILLs it when the thread that forked it ends
        (``prctl(PR_SET_PDEATHSIG)``), and it exits at once if that parent,
        ``parent_pid``, is gone already (it was reparented);
    -   in a process that multiprocessing started (a worker, forked by a
        fork server, whose own parent is that fork server), a thread waits
        on the pipe whose other end the process that started it (the
        server) holds, and kills the process when the pipe ends.

    The fork server calls it, and so does each process forked from it.
    ``prctl`` is skipped where it is missing (not Linux).
    """
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        prctl = None
    if prctl is not None and prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_PDEATHSIG) failed")
    if parent_pid is not None and os.getppid() != parent_pid:
        os._exit(1)
    starter = multiprocessing.parent_process()
    if starter is not None and starter.sentinel is not None:
        threading.Thread(target=_kill_at_end_of, args=(starter.sentinel,), name="end-with-server", daemon=True).start()


def _kill_at_end_of(sentinel: int) -> None:
    wait([sentinel])
    os.kill(os.getpid(), signal.SIGKILL)


def worker_start(cancelled) -> None:
    """
    Each worker's initializer: it ends with the server
    (:func:`end_with_parent`), the shared cancellation ring, the warm-up,
    then one BLAS thread for the process's life (after the warm-up: a limit
    applies only to the BLAS libraries already loaded).
    """
    global _cancelled
    from threadpoolctl import threadpool_limits

    end_with_parent()
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


PRELOAD = ("service.runtime.preload",)
"""What the fork server imports once, so that each process forked from it starts with it (:mod:`service.runtime.preload`)."""


def process_context():
    """
    The start method of the fitting and render processes: ``forkserver``
    with :data:`PRELOAD`. The fork server is a single-threaded process (no
    GL context, no open connections of the server) that imported the
    fitting core and colour-science once; each worker is a fork of it.
    Forking the server itself would copy its threads' locks mid-use;
    spawning imports the core again in every worker. The service's entry
    point (``python -m service``) forks the fork server from itself before
    any thread starts (:func:`service.runtime.fork_server.start_fork_server`); elsewhere (an application
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
