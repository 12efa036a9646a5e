"""
Render pool
===========

The process pool that draws previews and GL textures, apart from the
fitting pool and off the server process.

-   :class:`PreviewRunner`: ``workers`` render processes (forked by the fork server, :func:`service.runtime.worker.process_context`), each
    with its own GL context made on its own render thread
    (:mod:`service.runtime.render_worker`); previews bounded in flight, textures
    bounded waiting; identical requests in flight share one render; a time
    limit per request, the CPU-time limit per job, cancellation.
-   :class:`PreviewsBusy`, :class:`PreviewTimeout`, :class:`RenderWorkerLost`,
    :class:`RendererUnavailable`: why a render was not answered (503 with
    ``Retry-After``, 504 with ``Retry-After``, 503 with ``Retry-After``, 503).

Why processes: a preview is seconds of numpy (the spectral reference),
GL read-back and PNG encoding. In threads of the server process it held
the GIL for long stretches, and the event loop (``/healthz`` too) stalled
behind it (item 8). Here the server only sends a fit's packed
material and n, k and receives the PNG bytes; the event loop never waits
on a render.

Bounds and budgets:

-   At most ``workers`` (``COATED_MAX_PREVIEWS_IN_FLIGHT``) previews render
    at once; a new preview past that is refused at once (:class:`PreviewsBusy`)
    rather than queued. A request that joins an identical preview in
    flight takes no place of its own.
-   Textures (the prefiltered environments: milliseconds once a process
    has them, seconds the first time) wait for a worker; at most
    :data:`TEXTURE_QUEUE` at once, then :class:`PreviewsBusy`.
-   A request waits at most ``timeout_s`` (``COATED_PREVIEW_TIMEOUT_S``;
    :class:`PreviewTimeout`); each job may use ``cpu_limit_s`` of CPU
    (``COATED_JOB_CPU_LIMIT_S``; :class:`service.runtime.worker.JobCPULimit`, 422).
-   A preview comes with its estimated CPU seconds (``cost_s``): its budget
    is proportional to it (:func:`service.runtime.budget.render_budget_s`:
    :class:`~service.runtime.budget.RenderBudgetExceeded`, 422, past it; the
    process stays and serves the next job), and one whose estimate passes
    ``cpu_limit_s`` is refused before it starts
    (:class:`~service.runtime.budget.RenderTooCostly`, 422). A client's
    previews in flight are admitted by their estimates: past its first,
    together at most ``client_cost_s`` (``COATED_JOB_CPU_LIMIT_S``), or
    :class:`PreviewsBusy` (503) while other clients keep their places.
-   A job no request waits for any more (each timed out, or its client
    went away: :class:`service.api.middleware.RequestLimits` cancels the
    request) is cancelled: its process checks every 0.1 s
    (:func:`service.runtime.worker.run_part`) and stops at its next check; one
    that has not stopped :data:`CANCEL_GRACE_S` later (in a long numpy
    call, or starved of CPU) is stopped (SIGKILL) and another started for
    the next job. A preview's place is held until its process is free of
    it, not only until its request ends, so the bound counts the work
    really running.
-   Each render process is an executor of its own: a process that dies
    (or is stopped) fails only its own jobs (:class:`RenderWorkerLost`),
    and another is started for the next job; a render is not tried again
    (one that killed its process would kill the next). So does one that
    could not be started (its fork server died:
    :data:`service.runtime.fork_server.START_ERRORS`), once the fork server's exit
    is seen, so that the next starts from another.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import logging
import math
import os
import signal
import threading
import time
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable

from . import executors
from .fork_server import START_ERRORS, fork_server_exited
from .budget import RenderBudgetExceeded, render_budget_s
from .pool import FitTimeout, Overloaded, WorkerLost
from .render_worker import RendererUnavailable, render_worker_start, run_render_part
from .flights import CancelRing, Flights
from .shares import CLAIM
from .worker import JobCPULimit, process_context

__all__ = [
    "PreviewRunner",
    "PreviewsBusy",
    "PreviewTimeout",
    "RenderWorkerLost",
    "RendererUnavailable",
    "TEXTURE_QUEUE",
    "CANCEL_GRACE_S",
]

log = logging.getLogger("service.runtime.previews")

TEXTURE_QUEUE = 16
"""Texture jobs in flight (running or waiting for a render process) at most; past it 503."""
CANCEL_GRACE_S = 2.0
"""A cancelled job still running this long after (its process did not reach a check: a long
numpy call, or a process starved of CPU) has its process stopped (SIGKILL) and replaced."""


class PreviewsBusy(Overloaded):
    """Previews (or textures) in flight at the bound; ``retry_after`` in seconds (503)."""

    def __init__(self, retry_after: int, what: str) -> None:
        Exception.__init__(self, f"{what}; retry in about {retry_after} s")
        self.retry_after = retry_after


class PreviewTimeout(FitTimeout):
    """A render request waited past its time limit (504); its job was cancelled."""

    def __init__(self, limit_s: float) -> None:
        Exception.__init__(
            self,
            f"the render did not finish within the time limit of {limit_s:g} s "
            "(COATED_PREVIEW_TIMEOUT_S); it was cancelled (a smaller preview `size` renders faster)",
        )
        self.retry_after = max(1, math.ceil(limit_s / 4))


class RenderWorkerLost(WorkerLost):
    """The render process of a job died (503); another is started for the next job."""

    def __init__(
        self, message: str = "the render process of this preview died; another is started for the next one"
    ) -> None:
        Exception.__init__(self, message)
        self.retry_after = 1


class _RenderProcess:
    """
    One render process: an executor of one worker (so that stopping it
    touches no other job), its pid once known, its jobs submitted and not
    ended, and whether it is broken (replaced on the next job).
    """

    def __init__(self, context, cancelled) -> None:
        self.executor = concurrent.futures.ProcessPoolExecutor(
            max_workers=1, mp_context=context, initializer=render_worker_start, initargs=(cancelled,)
        )
        self.pid: int | None = None
        self.jobs = 0
        self.broken = False


class PreviewRunner:
    """
    The render pool (see the module docstring).

    :meth:`preview` and :meth:`texture` run ``function(*args)`` in a render
    process (``function`` module-level, so that it pickles: the jobs of
    :mod:`service.jobs.previews` and :mod:`service.jobs.textures`) and
    return its result; concurrent calls with the same ``key`` share one
    job. The processes start on the first jobs; a job goes to the process
    with the fewest jobs.
    """

    def __init__(
        self,
        workers: int,
        timeout_s: float,
        cpu_limit_s: float,
        texture_queue: int = TEXTURE_QUEUE,
        cancel_grace_s: float = CANCEL_GRACE_S,
        client_cost_s: float | None = None,
    ) -> None:
        if workers < 1:
            raise ValueError(f"`workers` must be >= 1, got {workers}")
        self.workers = workers
        self.timeout_s = timeout_s
        self.cpu_limit_s = cpu_limit_s
        self.client_cost_s = cpu_limit_s if client_cost_s is None else client_cost_s
        self._by_client: dict[str, tuple[int, float]] = {}  # client -> (previews in flight, their estimate)
        self.texture_queue = texture_queue
        self.cancel_grace_s = cancel_grace_s
        self._context = process_context()
        self._cancels = CancelRing(self._context)
        self._serial = 0
        self._lock = threading.Lock()  # counts are released from the executors' threads
        self._processes: list[_RenderProcess | None] = [None] * workers
        self._counts = {"preview": 0, "texture": 0}
        self._running: dict[int, concurrent.futures.Future] = {}
        self._flights = Flights()
        self._mean_s = 4.0  # running estimate of one preview's seconds, for Retry-After
        self.restarts = 0

    @property
    def previews_in_flight(self) -> int:
        """Previews whose render process is busy with them (or about to be)."""
        return self._counts["preview"]

    def _take_process(self) -> _RenderProcess:
        """The process with the fewest jobs (a missing or broken one made anew), one job more."""
        with self._lock:
            for index, process in enumerate(self._processes):
                if process is None or process.broken:
                    self._processes[index] = _RenderProcess(self._context, self._cancels.shared)
            process = min(self._processes, key=lambda p: p.jobs)
            process.jobs += 1
            return process

    def _end_job(self, process: _RenderProcess) -> None:
        with self._lock:
            process.jobs -= 1

    def _break(self, process: _RenderProcess, kill: bool = False) -> None:
        """Give up ``process`` (``kill``: stop it now, SIGKILL); the next job starts another."""
        with self._lock:
            if process.broken:
                return
            process.broken = True
            self.restarts += 1
        if kill and process.pid is not None:
            with contextlib.suppress(ProcessLookupError):
                os.kill(process.pid, signal.SIGKILL)
            # Killed while it sent a result, it would leave the executor waiting for the rest forever, its
            # jobs' places never left (service.runtime.executors): the executor reads end of file instead.
            executors.unstick(process.executor)
        # Jobs queued behind it fail with the process (BrokenProcessPool: 503), not as cancelled.
        process.executor.shutdown(wait=False)

    def _admit(self, what: str, client: str, cost_s: float) -> None:
        """Take a place of ``what`` ("preview" | "texture") for ``client``'s job of ``cost_s``
        estimated CPU seconds, or refuse (:class:`PreviewsBusy`)."""
        limit = self.workers if what == "preview" else self.texture_queue
        with self._lock:
            waves = math.ceil(max(self._counts["preview"], 1) / self.workers)
            retry = max(1, math.ceil(waves * self._mean_s))
            if self._counts[what] >= limit:
                raise PreviewsBusy(
                    retry,
                    (
                        f"{limit} previews are being rendered (COATED_MAX_PREVIEWS_IN_FLIGHT)"
                        if what == "preview"
                        else f"{limit} textures are waiting for a render process"
                    ),
                )
            held, cost = self._by_client.get(client, (0, 0.0))
            if what == "preview" and held and cost + cost_s > self.client_cost_s:
                raise PreviewsBusy(
                    retry,
                    (
                        f"this client's previews in flight are estimated at {cost:.1f} s of CPU; with this one's "
                        f"{cost_s:.1f} s they would pass its share, {self.client_cost_s:g} s (COATED_JOB_CPU_LIMIT_S)"
                    ),
                )
            self._counts[what] += 1
            if what == "preview":
                self._by_client[client] = (held + 1, cost + cost_s)

    def _leave(self, what: str, started: float | None = None, share: tuple[str, float] = ("", 0.0)) -> None:
        with self._lock:
            self._counts[what] -= 1
            if what == "preview":
                held, cost = self._by_client.pop(share[0], (1, 0.0))
                if held > 1:
                    self._by_client[share[0]] = (held - 1, max(0.0, cost - share[1]))
            if started is not None and what == "preview":
                self._mean_s = 0.8 * self._mean_s + 0.2 * (time.perf_counter() - started)

    async def _job(
        self,
        what: str,
        function: Callable[..., Any],
        args: tuple,
        submitted: list,
        share: tuple[str, float],
        budget_s: float,
    ) -> Any:
        """
        One job in a render process; its place is left when its process is
        free of it (before it was submitted: when its task ends, :meth:`_once`).
        """
        process = self._take_process()
        with self._lock:
            self._serial += 1
            serial = self._serial
        started = time.perf_counter()
        try:
            if process.pid is None:  # the process starts (with its GL context) and says who it is
                process.pid = await asyncio.wrap_future(process.executor.submit(os.getpid))
            future = process.executor.submit(run_render_part, serial, budget_s, function, *args)
        except BaseException as error:
            self._end_job(process)
            if isinstance(error, START_ERRORS):
                # Its fork server died or is dying: the next job's process starts from another.
                self._break(process)
                await fork_server_exited()
                raise RenderWorkerLost(
                    "the render process of this preview could not be started (its fork server "
                    "died); another is started for the next one"
                ) from None
            if isinstance(error, (BrokenProcessPool, RuntimeError)):
                self._break(process)
                raise RenderWorkerLost() from None
            raise
        submitted.append(serial)
        self._running[serial] = future

        def done(f: concurrent.futures.Future) -> None:
            self._running.pop(serial, None)
            self._end_job(process)
            failed = f.cancelled() or f.exception() is not None
            self._leave(what, None if failed else started, share)
            if not f.cancelled() and isinstance(f.exception(), BrokenProcessPool):
                self._break(process)

        future.add_done_callback(done)
        try:
            return await executors.result(process.executor, future)  # stuck on a killed process's result: broken
        except BrokenProcessPool:
            raise RenderWorkerLost() from None
        except JobCPULimit:
            if budget_s >= self.cpu_limit_s:
                raise
            raise RenderBudgetExceeded(budget_s, share[1]) from None
        except asyncio.CancelledError:
            self._cancels.cancel(serial, future)
            asyncio.get_running_loop().call_later(self.cancel_grace_s, self._stop_if_running, process, future)
            raise

    def _stop_if_running(self, process: _RenderProcess, future: concurrent.futures.Future) -> None:
        """A cancelled job still running ``cancel_grace_s`` later (in a long numpy call, or
        starved of CPU): its process is stopped, and the next job starts another."""
        if future.done():
            return
        log.warning("a cancelled render did not stop within %g s; its render process was stopped", self.cancel_grace_s)
        self._break(process, kill=True)

    async def _once(
        self, what: str, key: tuple, function: Callable[..., Any], args: tuple, cost_s: float | None = None
    ) -> Any:
        """
        ``function(*args)`` as one job shared by the calls with ``key``, within the time limit;
        with ``cost_s`` (estimated CPU seconds) its budget proportional to it, else the CPU-time limit.
        """
        key = (what, *key)
        budget_s = self.cpu_limit_s if cost_s is None else render_budget_s(cost_s, self.cpu_limit_s)

        def start() -> asyncio.Task:
            share = (CLAIM.get().client, cost_s or 0.0)
            self._admit(what, *share)
            submitted: list[int] = []
            task = asyncio.ensure_future(self._job(what, function, args, submitted, share, budget_s))

            def finished(t: asyncio.Task) -> None:
                if not submitted:  # cancelled or refused before its process had it
                    self._leave(what, None, share)

            task.add_done_callback(finished)
            return task

        task = self._flights.start(key, start)
        return await self._flights.join(key, task, self.timeout_s, lambda: PreviewTimeout(self.timeout_s))

    async def preview(self, key: tuple, function: Callable[..., Any], *args: Any, cost_s: float | None = None) -> Any:
        """
        A preview: refused at once past ``workers`` in flight, or past its
        client's share of estimated CPU seconds; ``cost_s``, its estimated
        CPU seconds, gives its budget (see the module docstring; None: the
        CPU-time limit).

        Raises
        ------
        PreviewsBusy, PreviewTimeout, RenderWorkerLost, RendererUnavailable, JobCPULimit,
        RenderTooCostly, RenderBudgetExceeded, ValueError
        """
        return await self._once("preview", key, function, args, cost_s)

    async def texture(self, key: tuple, function: Callable[..., Any], *args: Any) -> Any:
        """A texture: waits for a render process (at most :data:`TEXTURE_QUEUE` at once); as :meth:`preview`."""
        return await self._once("texture", key, function, args)

    def close(self) -> None:
        """Cancel what runs (stopped at once: the service is going) and stop the processes."""
        self._flights.cancel_all()
        with self._lock:
            processes = [p for p in self._processes if p is not None]
            self._processes = [None] * self.workers
        for process in processes:
            if process.jobs:
                self._break(process, kill=True)
            process.executor.shutdown(wait=True, cancel_futures=True)
