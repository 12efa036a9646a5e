"""
Process executors' results
==========================

What Python's ``ProcessPoolExecutor`` (3.11-3.13) does not do for the
fitting and render pools (:mod:`service.runtime.pool`, :mod:`service.runtime.previews`):
see a worker that was killed while it wrote a result.

A worker sends a result of over 16 KB in two writes to the pipe all the
workers share (a header with its length, then the payload, which a pipe
takes 64 KB at a time while the reader drains it). Killed between them or
during the second (by the OOM killer, an administrator, or the render pool
stopping a render that did not stop), it leaves the executor's manager
thread waiting in ``recv()`` for the rest of a message that never comes:
the other workers, and this process itself, hold the pipe's write end, so
no end of file comes either. The thread then never looks at the workers
again, so the pool never breaks: every job in it, and every later one,
waits forever, and its shutdown hangs (``benchmarks/stuck_pools.py``
measures how often, with and without :func:`result`).

:func:`result` awaits a job's future and watches its executor's workers:
a worker dead for :data:`STUCK_S` in a pool that has not broken is that
case, and :func:`unstick` kills the executor's workers and closes this
process's end of the pipe, so the manager thread reads end of file and
breaks the pool as for any dead worker (``BrokenProcessPool`` for its
jobs, which the pools handle).
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import logging
import time
from multiprocessing import connection
from typing import Any

from .mp_private import close_result_pipe, executor_processes

__all__ = ["STUCK_S", "WATCH_S", "has_dead_worker", "unstick", "result"]

log = logging.getLogger("service.runtime.executors")

STUCK_S = 3.0
"""How long a worker may be dead in a pool that has not broken before :func:`unstick` (the manager
thread breaks a pool within milliseconds of a death it sees)."""

WATCH_S = 0.5
"""How often :func:`result` looks at the workers while it waits."""


def has_dead_worker(executor: concurrent.futures.ProcessPoolExecutor) -> bool:
    """
    Whether a worker process of ``executor`` has ended (its sentinel is
    ready; read, not consumed). ``False`` for an executor shut down, with
    no workers yet, or of a Python that keeps them elsewhere.
    """
    processes = executor_processes(executor)
    if not processes:
        return False
    try:
        sentinels = [process.sentinel for process in list(processes.values())]
    except (RuntimeError, AttributeError, ValueError):  # changed by the manager thread meanwhile, or closed
        return False
    try:
        return bool(connection.wait(sentinels, 0))
    except (OSError, ValueError):  # a sentinel closed meanwhile: the pool is being shut down
        return False


def unstick(executor: concurrent.futures.ProcessPoolExecutor) -> None:
    """
    Kill ``executor``'s worker processes and close this process's end of
    the pipe they send results on, so that a manager thread waiting for
    the rest of a result reads end of file and breaks the pool (its jobs
    fail with ``BrokenProcessPool``). Harmless to a pool whose manager
    thread is not stuck: it breaks the pool for the dead workers.
    """
    processes = executor_processes(executor)
    for process in list(processes.values()):
        with contextlib.suppress(OSError, ValueError, AttributeError):
            process.kill()
    close_result_pipe(executor)


async def result(
    executor: concurrent.futures.ProcessPoolExecutor,
    future: concurrent.futures.Future,
    stuck_s: float = STUCK_S,
    watch_s: float = WATCH_S,
) -> Any:
    """
    ``future``'s result (a job of ``executor``), or its exception; as
    ``await asyncio.wrap_future(future)`` (cancelling the await cancels
    the future), and a pool whose worker died while it wrote a result is
    unstuck (:func:`unstick`) once the worker has been dead ``stuck_s``
    without the pool breaking: its jobs then fail with ``BrokenProcessPool``.
    """
    wrapped = asyncio.wrap_future(future)
    dead_since = None
    try:
        while True:
            done, _ = await asyncio.wait({wrapped}, timeout=watch_s)
            if done:
                return wrapped.result()
            if not has_dead_worker(executor):
                dead_since = None
            elif dead_since is None:
                dead_since = time.monotonic()
            elif time.monotonic() - dead_since >= stuck_s:
                log.warning(
                    "a worker process died while it sent a result, and its pool did not see it; "
                    "the pool was stopped (its jobs run again as after any worker's death)"
                )
                unstick(executor)
                dead_since = None
    except asyncio.CancelledError:
        wrapped.cancel()
        raise
