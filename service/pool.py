"""
Fitting pool
============

The bounded process pool every kind of fit runs in (:mod:`service.jobs`).

-   :class:`FitRunner`: worker processes (``spawn``), a bound on jobs in
    flight, a time limit per request, shared identical jobs, jobs of parts
    run side by side, and recovery from a dead worker.
-   :class:`Overloaded`, :class:`FitTimeout`, :class:`WorkerLost`,
    :class:`JobCPULimit`: why a job was not answered (the HTTP edge answers
    503, 504, 503 and 422, the first three with ``Retry-After``).

Fitting is CPU-bound (numpy, scipy): it runs in worker processes started
with ``spawn`` (forking a process that already runs threads or holds a GL
context is unsafe), never on the event loop. The number of jobs running or
waiting is bounded; past the bound a job is refused at once with a
``Retry-After`` estimate instead of growing a backlog.

Faults:

-   A worker that dies breaks the whole ``ProcessPoolExecutor`` (every job in
    it fails with ``BrokenProcessPool``). The runner replaces the pool, warms
    the new workers at once, and runs each interrupted job (or part of one)
    once more there; only a job that fails twice is answered
    :class:`WorkerLost`. So a dead worker fails at most its own job (when it
    kills its worker again).
-   A request that waits past the time limit gets :class:`FitTimeout`, and
    its job is cancelled when no other request waits for it (as when every
    client waiting for it has gone): its worker checks every 0.1 s and is
    free within a second.
-   Each part of a job has a CPU-time limit (``cpu_limit_s``), checked by
    its worker every 0.1 s: past it the part stops with
    :class:`JobCPULimit`. BLAS runs one thread per worker (the fits'
    matrices are tiny; threads there only contend for the cores).
"""

from __future__ import annotations

import asyncio
import collections
import concurrent.futures
import contextlib
import logging
import math
import multiprocessing
import signal
import threading
import time
from concurrent.futures.process import BrokenProcessPool
from typing import Any, AsyncIterator, Awaitable, Callable

__all__ = ["FitRunner", "Overloaded", "FitTimeout", "WorkerLost", "JobCPULimit"]

log = logging.getLogger("service.pool")


class Overloaded(Exception):
    """Too many jobs in flight; ``retry_after`` is a wait estimate in seconds."""

    def __init__(self, retry_after: int, limit: int) -> None:
        super().__init__(
            f"the service is fitting {limit} materials already (the limit); "
            f"retry in about {retry_after} s"
        )
        self.retry_after = retry_after


class FitTimeout(Exception):
    """A request waited past the time limit; its job goes on and keeps its result."""

    def __init__(self, limit_s: float, retry_after: int = 1) -> None:
        super().__init__(
            f"the fit did not finish within the time limit of {limit_s:g} s "
            "(COATED_FIT_TIMEOUT_S); it was cancelled"
        )
        self.retry_after = retry_after


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


class WorkerLost(Exception):
    """A worker process died during the job twice (it was retried once)."""

    retry_after = 1

    def __init__(self) -> None:
        super().__init__("a fitting worker process stopped during the fit (twice); retry")


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


_CANCEL_SLOTS = 256  # cancelled job serials remembered (a ring); far more than jobs in flight
_CHECK_S = 0.1  # how often a worker checks its job's CPU time and cancellation
_cancelled = None  # in a worker: the server's shared ring of cancelled job serials


def _worker_start(cancelled) -> None:
    """Each worker's initializer: one BLAS thread, the shared cancellation ring, warm-up."""
    global _cancelled
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1)
    _cancelled = cancelled
    warm_process()


def _run_part(serial: int, cpu_limit_s: float, function: Callable[..., Any], *args: Any) -> Any:
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
            raise JobCPULimit(cpu_limit_s)

    previous = signal.signal(signal.SIGALRM, check)
    signal.setitimer(signal.ITIMER_REAL, _CHECK_S, _CHECK_S)
    try:
        return function(*args)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


def _ping() -> float:
    time.sleep(0.05)  # long enough that each warm-up ping lands on its own worker
    return time.time()


class FitRunner:
    """
    The bounded fitting pool.

    ``max_in_flight`` jobs may run or wait at once; the next is refused with
    :class:`Overloaded`. A request waits at most ``timeout_s`` seconds
    (:meth:`once`); its job's slot stays taken until the job ends, so the
    bound stays true. A job is one function (:meth:`run`) or parts
    submitted under one slot (:meth:`slot`, :meth:`submit`), which idle
    workers run side by side. Each part may use ``cpu_limit_s`` seconds
    of CPU time (:class:`JobCPULimit`).
    """

    def __init__(self, workers: int, max_in_flight: int, timeout_s: float, cpu_limit_s: float = 60.0) -> None:
        if workers < 1 or max_in_flight < workers:
            raise ValueError(
                f"`max_in_flight` ({max_in_flight}) must be >= `workers` ({workers}) >= 1"
            )
        self.workers = workers
        self.max_in_flight = max_in_flight
        self.timeout_s = timeout_s
        self.cpu_limit_s = cpu_limit_s
        context = multiprocessing.get_context("spawn")
        self._context = context
        self._cancelled = context.Array("q", [-1] * _CANCEL_SLOTS, lock=False)
        self._cancel_next = 0
        self._serial = 0
        self._waiters: collections.Counter[str] = collections.Counter()
        self._lock = threading.Lock()
        self._in_flight = 0
        self._mean_s = 2.0  # running estimate of one job's duration, for Retry-After
        self._pool: concurrent.futures.ProcessPoolExecutor | None = None
        self._pending: dict[str, asyncio.Task] = {}
        self._warming: set[asyncio.Task] = set()
        self.completed = 0
        self.restarts = 0

    @property
    def in_flight(self) -> int:
        return self._in_flight

    def _executor(self) -> concurrent.futures.ProcessPoolExecutor:
        with self._lock:
            if self._pool is None:
                self._pool = concurrent.futures.ProcessPoolExecutor(
                    max_workers=self.workers,
                    mp_context=self._context,
                    initializer=_worker_start,
                    initargs=(self._cancelled,),
                )
            return self._pool

    def _restart(self, broken: concurrent.futures.ProcessPoolExecutor) -> None:
        """Replace a broken pool (once, however many jobs saw it break) and warm the new one."""
        with self._lock:
            replaced = self._pool is broken
            if replaced:
                self._pool = None
                self.restarts += 1
        broken.shutdown(wait=False, cancel_futures=True)
        if replaced:
            log.warning("a fitting worker died; the pool was restarted (interrupted jobs run once more)")
            try:
                task = asyncio.get_running_loop().create_task(self.warm_up())
            except RuntimeError:
                return
            self._warming.add(task)
            task.add_done_callback(self._warming.discard)

    async def warm_up(self) -> None:
        """Start every worker process and wait until each has imported the core."""
        loop = asyncio.get_running_loop()
        pool = self._executor()
        try:
            await asyncio.gather(*(loop.run_in_executor(pool, _ping) for _ in range(self.workers)))
        except (BrokenProcessPool, RuntimeError):
            pass  # a pool that broke while warming is replaced by the job that sees it

    def _retry_after(self) -> int:
        waves = math.ceil(max(self._in_flight, 1) / self.workers)
        return max(1, math.ceil(waves * self._mean_s))

    def check_capacity(self) -> None:
        """
        Refuse (:class:`Overloaded`) at once when the pool is full, before a
        request spends CPU on validating its input; :meth:`run` checks again.
        """
        if self._in_flight >= self.max_in_flight:
            raise Overloaded(self._retry_after(), self.max_in_flight)

    def _acquire(self) -> None:
        with self._lock:
            if self._in_flight >= self.max_in_flight:
                raise Overloaded(self._retry_after(), self.max_in_flight)
            self._in_flight += 1

    def _release(self, started: float | None) -> None:
        with self._lock:
            self._in_flight -= 1
            if started is not None:
                self.completed += 1
                self._mean_s = 0.8 * self._mean_s + 0.2 * (time.perf_counter() - started)

    @contextlib.asynccontextmanager
    async def slot(self) -> AsyncIterator[None]:
        """
        One place in the bound for a job of one or more parts
        (:meth:`submit`), held until the job ends; a job that ends without
        an exception counts as completed and updates the wait estimate.

        Raises
        ------
        Overloaded
        """
        self._acquire()
        started = time.perf_counter()
        done = None
        try:
            yield
            done = started
        finally:
            self._release(done)

    async def submit(self, function: Callable[..., Any], *args: Any) -> Any:
        """
        Run ``function(*args)`` in a worker as one part of a job that holds
        a :meth:`slot`; its exceptions (ValueError for bad input) are raised
        here. A part interrupted by a dead worker runs once more on the
        replacement pool.

        Raises
        ------
        WorkerLost
        """
        for attempt in (1, 2):
            pool = self._executor()
            with self._lock:
                self._serial += 1
                serial = self._serial
            try:
                future = pool.submit(_run_part, serial, self.cpu_limit_s, function, *args)
                return await asyncio.wrap_future(future)
            except asyncio.CancelledError:
                self._cancel(serial, future)
                raise
            except (BrokenProcessPool, RuntimeError) as error:
                if not isinstance(error, BrokenProcessPool) and "shutdown" not in str(error):
                    raise
                self._restart(pool)
                if attempt == 2:
                    raise WorkerLost() from None

    def _cancel(self, serial: int, future: concurrent.futures.Future) -> None:
        """Stop a part: dropped if still queued, else its worker stops at its next check."""
        if future.cancel():
            return
        with self._lock:
            self._cancelled[self._cancel_next % _CANCEL_SLOTS] = serial
            self._cancel_next += 1

    async def run(self, function: Callable[..., Any], *args: Any) -> Any:
        """
        Run ``function(*args)`` in a worker as a job of one part (a
        :meth:`slot` and :meth:`submit`), without a time limit (the
        request's limit is :meth:`once`'s).

        Raises
        ------
        Overloaded, WorkerLost
        """
        async with self.slot():
            return await self.submit(function, *args)

    async def once(self, key: str, make: Callable[[], Awaitable[Any]]) -> Any:
        """
        Await ``make()`` for at most ``timeout_s`` seconds, shared by
        concurrent calls with the same ``key``. Past the limit the caller
        gets :class:`FitTimeout`; a job that no caller waits for any more
        (each timed out or was cancelled, as when its client went away) is
        cancelled, its worker free within a second.
        """
        task = self._pending.get(key)
        if task is None:
            task = asyncio.ensure_future(make())
            self._pending[key] = task
            task.add_done_callback(lambda t: self._pending.pop(key, None))
        self._waiters[key] += 1
        try:
            return await asyncio.wait_for(asyncio.shield(task), self.timeout_s)
        except asyncio.TimeoutError:
            raise FitTimeout(self.timeout_s, self._retry_after()) from None
        finally:
            self._waiters[key] -= 1
            if self._waiters[key] <= 0:
                del self._waiters[key]
                if not task.done():
                    task.cancel()

    def close(self) -> None:
        for task in [*self._pending.values(), *self._warming]:
            task.cancel()
        with self._lock:
            pool, self._pool = self._pool, None
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)
