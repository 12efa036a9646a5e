"""
Fitting pool
============

The bounded process pool every kind of fit runs in (:mod:`service.jobs`).

-   :class:`FitRunner`: worker processes (forked by a fork server), a bound on jobs in
    flight, a time limit per request, shared identical jobs, jobs of parts
    run side by side, and recovery from a dead worker.
-   :class:`Overloaded`, :class:`FitTimeout`, :class:`WorkerLost`,
    :class:`JobCPULimit`: why a job was not answered (the HTTP edge answers
    503, 504, 503 and 422, the first three with ``Retry-After``;
    :mod:`service.runtime.pool_errors`).
-   :attr:`FitRunner.cannot_start`: why no worker can be started now (what
    ``/healthz`` answers 503 with), None once one runs a part again.

Fitting is CPU-bound (numpy, scipy): it runs in worker processes, never on
the event loop, forked by a fork server (:func:`service.runtime.worker.process_context`).
The jobs running or waiting are bounded, past the bound refused at once with
a ``Retry-After`` estimate; bulk jobs (reads, packs, scenes) also within
their client's share, and saves first (:mod:`service.runtime.shares`).

Faults:

-   A worker that dies breaks the whole ``ProcessPoolExecutor`` (every job in
    it fails with ``BrokenProcessPool``). The runner replaces the pool, warms
    the new workers at once, and runs each interrupted part once more there;
    one interrupted twice runs alone, in a worker of its own (one at a time):
    only a part that kills that worker too is answered :class:`WorkerLost`,
    its job's content id refused for ``quarantine_s`` (:class:`Quarantined`).
-   A worker that cannot start (its fork server died:
    :data:`service.runtime.fork_server.START_ERRORS`) is not the part's doing: once
    the fork server's exit is seen, the pool is replaced (with a new fork
    server) and the part runs there (:class:`WorkersNotStarted` after three).
-   A pool stuck on a result its killed worker left half-written breaks
    (:mod:`service.runtime.executors`).
-   A request that waits past the time limit gets :class:`FitTimeout`; a job
    no request waits for is cancelled, its worker free within a second.
-   Each part of a job has a CPU-time limit (``cpu_limit_s``), checked by
    its worker every 0.1 s: past it the part stops with
    :class:`JobCPULimit`; each job has a CPU budget proportional to its
    estimated cost (:mod:`service.runtime.budget`). BLAS: one thread.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import contextvars
import logging
import math
import threading
import time
from concurrent.futures.process import BrokenProcessPool
from typing import Any, AsyncIterator, Awaitable, Callable

from . import executors
from .shares import CLAIM, Claim, Shares
from .pool_errors import FitTimeout, Overloaded, Quarantined, StartFailed, WorkerLost, WorkersNotStarted
from .turns import Turns
from .flights import CancelRing, Flights
from .fork_server import START_ERRORS, fork_server_exited
from .budget import BUDGET, JobBudget, JobBudgetExceeded, charged, part_limit, run_part_timed
from .worker import JobCPULimit, ping, process_context, warm_process, worker_start

__all__ = [
    "FitRunner",
    "Overloaded",
    "FitTimeout",
    "WorkerLost",
    "WorkersNotStarted",
    "Quarantined",
    "JobCPULimit",
    "JobBudgetExceeded",
    "warm_process",
]

log = logging.getLogger("service.runtime.pool")


EXPRESS_COST_S = 0.1
"""Parts estimated at most this many seconds (a library fit's parts, a live
step) may take an express turn (:class:`service.runtime.turns.Turns`)."""

_JOB_KEY: contextvars.ContextVar[str | None] = contextvars.ContextVar("job_key", default=None)
_QUARANTINE_KEYS = 1024  # content ids remembered at most


class FitRunner:
    """
    The bounded fitting pool: ``workers`` processes run parts of any cost, ``express_workers`` more
    only cheap ones (:data:`EXPRESS_COST_S`), so a library fit or a live
    step never waits for an expensive part to end.

    ``max_in_flight`` jobs may run or wait at once; the next is refused with
    :class:`Overloaded`. A request waits at most ``timeout_s`` seconds
    (:meth:`once`); its job's slot stays taken until the job ends, so the
    bound stays true. A job is one function (:meth:`run`) or parts
    submitted under one slot (:meth:`slot`, :meth:`submit`), which idle
    workers run side by side. Each part may use ``cpu_limit_s`` seconds of CPU time (:class:`JobCPULimit`).
    """

    def __init__(
        self,
        workers: int,
        max_in_flight: int,
        timeout_s: float,
        cpu_limit_s: float = 60.0,
        quarantine_s: float = 600.0,
        express_workers: int = 0,
        client_bulk_jobs: int | None = None,
    ) -> None:
        if workers < 1 or max_in_flight < workers:
            raise ValueError(f"`max_in_flight` ({max_in_flight}) must be >= `workers` ({workers}) >= 1")
        if express_workers < 0:
            raise ValueError(f"`express_workers` must be >= 0, got {express_workers}")
        self.workers = workers
        self.express_workers = express_workers
        self.max_in_flight = max_in_flight
        self.timeout_s = timeout_s
        self.cpu_limit_s = cpu_limit_s
        self.quarantine_s = quarantine_s
        self._quarantine: dict[str, float] = {}  # content id -> monotonic time it is refused until
        self._alone: concurrent.futures.ProcessPoolExecutor | None = None
        self._alone_lock = asyncio.Lock()
        self._turns = Turns(workers, express_workers, EXPRESS_COST_S)
        self.shares = Shares(
            max_in_flight, min(workers, max_in_flight - 1), client_bulk_jobs or workers, timeout_s * workers
        )  # a client's bulk jobs: what one request may use, in all
        self._context = process_context()
        self._cancels = CancelRing(self._context)
        self._serial = 0
        self._lock = threading.Lock()
        self._in_flight = 0
        self._mean_s = 2.0  # running estimate of one job's duration, for Retry-After
        self._pool: concurrent.futures.ProcessPoolExecutor | None = None
        self._flights = Flights()
        self._warming: set[asyncio.Task] = set()
        self.completed = 0
        self.restarts = 0
        self.cannot_start: str | None = None  # why no worker could be started, until one runs a part again

    @property
    def in_flight(self) -> int:
        return self._in_flight

    def _executor(self) -> concurrent.futures.ProcessPoolExecutor:
        with self._lock:
            if self._pool is None:
                self._pool = concurrent.futures.ProcessPoolExecutor(
                    max_workers=self.workers + self.express_workers,
                    mp_context=self._context,
                    initializer=worker_start,
                    initargs=(self._cancels.shared,),
                )
            return self._pool

    def _restart(
        self,
        broken: concurrent.futures.ProcessPoolExecutor,
        why: str = "a fitting worker died; the pool was restarted (interrupted jobs run once more)",
    ) -> None:
        """Replace a broken pool (once, however many jobs saw it break) and warm the new one; log ``why``."""
        with self._lock:
            replaced = self._pool is broken
            if replaced:
                self._pool = None
                self.restarts += 1
        broken.shutdown(wait=False, cancel_futures=True)
        if replaced:
            log.warning(why)
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
            await asyncio.gather(
                *(loop.run_in_executor(pool, ping) for _ in range(self.workers + self.express_workers))
            )
        except (BrokenProcessPool, RuntimeError, *START_ERRORS):
            pass  # a pool that broke (or could not start a worker) while warming is replaced by the job that sees it
        except OSError as error:  # no process could be started at all: set aside, tried again by the next start
            log.warning("no fitting worker could be started: %r", error)
            with self._lock:
                if self._pool is pool:
                    self._pool = None
            pool.shutdown(wait=False, cancel_futures=True)
        else:
            self.cannot_start = None

    def retry_start(self) -> None:
        """While no worker could be started (:attr:`cannot_start`): try again in the background (one try at once)."""
        if self.cannot_start is not None and not self._warming:
            task = asyncio.get_running_loop().create_task(self.warm_up())
            self._warming.add(task)
            task.add_done_callback(self._warming.discard)

    def _retry_after(self) -> int:
        waves = math.ceil(max(self._in_flight, 1) / self.workers)
        return max(1, math.ceil(waves * self._mean_s))

    def check_capacity(self) -> None:
        """Refuse (:class:`Overloaded`) a full pool before a request's input is read; :meth:`run` checks again."""
        if self._in_flight >= self.max_in_flight:
            raise Overloaded(self._retry_after(), self.max_in_flight)

    def _acquire(self, claim: Claim, cost_s: float) -> None:
        with self._lock:
            if self._in_flight >= self.max_in_flight:
                raise Overloaded(self._retry_after(), self.max_in_flight)
            self.shares.admit(claim, self._retry_after(), cost_s)  # a bulk job within its client's share
            self._in_flight += 1

    def _release(self, started: float | None, claim: Claim, cost_s: float) -> None:
        with self._lock:
            self.shares.leave(claim, cost_s)
            self._in_flight -= 1
            if started is not None:
                self.completed += 1
                self._mean_s = 0.8 * self._mean_s + 0.2 * (time.perf_counter() - started)

    @contextlib.asynccontextmanager
    async def slot(self, estimate_s: float = 0.0) -> AsyncIterator[None]:
        """
        One place in the bound for a job of one or more parts
        (:meth:`submit`), held until the job ends; a job that ends without
        an exception counts as completed and updates the wait estimate. Its
        parts share a CPU budget of ``estimate_s`` (estimated CPU seconds)
        times ``BUDGET_FACTOR``, at least ``cpu_limit_s``.

        Raises
        ------
        Overloaded, service.runtime.shares.ShareExceeded
        """
        claim = CLAIM.get()
        self._acquire(claim, estimate_s)
        started, done, budget = time.perf_counter(), None, BUDGET.set(JobBudget(estimate_s, self.cpu_limit_s))
        try:
            yield
            done = started
        finally:
            BUDGET.reset(budget)
            self._release(done, claim, estimate_s)

    async def submit(self, function: Callable[..., Any], *args: Any, cost_s: float = 1.0) -> Any:
        """
        Run ``function(*args)`` in a worker as one part of a job that holds
        a :meth:`slot`; its exceptions (ValueError for bad input) are raised
        here. Parts take turns in the workers, saves first, then the
        cheapest waiting (``cost_s``, its estimated seconds:
        :class:`service.runtime.turns.Turns`); its worker time is charged to its
        claim (:data:`service.runtime.shares.CLAIM`). A
        part interrupted by a dead worker runs once more on the replacement
        pool; one whose worker could not be started runs on a pool whose
        workers start (:class:`WorkersNotStarted` after three failures).

        Raises
        ------
        WorkerLost, WorkersNotStarted
        """
        interrupted = start_failures = 0
        claim = CLAIM.get()
        while interrupted < 2:
            pool = self._executor()
            try:
                async with self._turns.turn(cost_s, self.shares.rank(claim)):
                    return await self._run_in(pool, function, args)
            except StartFailed as error:
                # Not the part's doing: it runs on a pool whose workers start, at most twice more.
                self._restart(
                    pool,
                    f"a fitting worker could not be started ({error}); the pool was restarted with a new fork server",
                )
                start_failures += 1
                if start_failures > 2:
                    self.cannot_start = f"no fitting worker process could be started, three times: {error}"
                    raise error.not_started() from None
            except (BrokenProcessPool, RuntimeError) as error:
                if not isinstance(error, BrokenProcessPool) and "shutdown" not in str(error):
                    raise
                self._restart(pool)
                interrupted += 1
        # Interrupted twice: run alone in a worker of its own, where a death is its own.
        async with self._alone_lock:
            with self._lock:
                if self._alone is None:
                    self._alone = concurrent.futures.ProcessPoolExecutor(
                        max_workers=1,
                        mp_context=self._context,
                        initializer=worker_start,
                        initargs=(self._cancels.shared,),
                    )
                alone = self._alone
            try:
                return await self._run_in(alone, function, args)
            except BrokenProcessPool as error:
                with self._lock:
                    self._alone = None
                alone.shutdown(wait=False, cancel_futures=True)
                if isinstance(error, StartFailed):
                    self.cannot_start = f"no fitting worker process could be started: {error}"
                    raise error.not_started() from None
                self._quarantine_current()
                raise WorkerLost(self.quarantine_s) from None

    async def _run_in(self, pool: concurrent.futures.ProcessPoolExecutor, function, args) -> Any:
        with self._lock:
            self._serial += 1
            serial = self._serial
        budget, limit_s = part_limit(self.cpu_limit_s)
        try:
            future = pool.submit(run_part_timed, serial, limit_s, function, *args)  # starts missing workers
        except START_ERRORS as error:
            # The fork server died or is dying: wait until multiprocessing can see that it has exited, so
            # that the pool replacing this one starts another instead of asking it again.
            await fork_server_exited()
            raise StartFailed() from error
        except OSError as error:  # no fork server or process could be made (its socket, no memory, no pid)
            raise StartFailed(repr(error)) from error
        began = time.perf_counter()
        try:  # a pool stuck on a killed worker's result breaks
            result = await charged(executors.result(pool, future), budget, limit_s, self.cpu_limit_s)
            self.cannot_start = None  # a worker ran it: workers start again
            return result
        except asyncio.CancelledError:
            self._cancels.cancel(serial, future)
            raise
        finally:
            self.shares.charge(CLAIM.get(), time.perf_counter() - began)

    def _quarantine_current(self) -> None:
        """Refuse the content id of the job in this context for ``quarantine_s``."""
        key = _JOB_KEY.get()
        if key is None:
            return
        now = time.monotonic()
        with self._lock:
            for old in [k for k, until in self._quarantine.items() if until <= now]:
                del self._quarantine[old]
            if len(self._quarantine) >= _QUARANTINE_KEYS:
                self._quarantine.pop(next(iter(self._quarantine)))
            self._quarantine[key] = now + self.quarantine_s
        log.warning("job %s stopped its worker three times; refused for %g s", key[:40], self.quarantine_s)

    async def run(self, function: Callable[..., Any], *args: Any, cost_s: float = 1.0) -> Any:
        """
        Run ``function(*args)`` in a worker as a job of one part (a
        :meth:`slot` and :meth:`submit`), without a time limit (the
        request's limit is :meth:`once`'s).

        Raises
        ------
        Overloaded, WorkerLost
        """
        async with self.slot(cost_s):
            return await self.submit(function, *args, cost_s=cost_s)

    async def once(self, key: str, make: Callable[[], Awaitable[Any]]) -> Any:
        """
        Await ``make()`` for at most ``timeout_s`` seconds, shared by
        concurrent calls with the same ``key``. Past the limit the caller
        gets :class:`FitTimeout`; a job that no caller waits for any more
        (each timed out or was cancelled, as when its client went away) is
        cancelled, its worker free within a second.
        """
        left = self._quarantine.get(key, 0.0) - time.monotonic()
        if left > 0:
            raise Quarantined(left)

        def start() -> asyncio.Task:
            token = _JOB_KEY.set(key)  # the job's task (a copy of this context) knows its content id
            try:
                return asyncio.ensure_future(make())
            finally:
                _JOB_KEY.reset(token)

        task = self._flights.start(key, start)
        return await self._flights.join(
            key, task, self.timeout_s, lambda: FitTimeout(self.timeout_s, self._retry_after())
        )

    def close(self) -> None:
        self._flights.cancel_all()
        for task in self._warming:
            task.cancel()
        with self._lock:
            pools, self._pool, self._alone = (self._pool, self._alone), None, None
        for pool in pools:
            if pool is not None:
                if executors.has_dead_worker(pool):  # its manager thread may wait for a result forever
                    executors.unstick(pool)
                pool.shutdown(wait=True, cancel_futures=True)
