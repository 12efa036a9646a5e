"""
Render pool
===========

The process pool that draws previews and GL textures, apart from the
fitting pool and off the server process.

-   :class:`PreviewRunner`: ``workers`` render processes (``spawn``), each
    with its own GL context made on its own render thread
    (:mod:`service.render_worker`); previews bounded in flight, textures
    bounded waiting; identical requests in flight share one render; a time
    limit per request, the CPU-time limit per job, cancellation.
-   :class:`PreviewsBusy`, :class:`PreviewTimeout`, :class:`RenderWorkerLost`,
    :class:`RendererUnavailable`: why a render was not answered (503 with
    ``Retry-After``, 504 with ``Retry-After``, 503 with ``Retry-After``, 503).

Why processes: a preview is seconds of numpy (the spectral reference),
GL read-back and PNG encoding. In threads of the server process it held
the GIL for long stretches, and the event loop (``/healthz`` too) stalled
behind it (issue 20, item 8). Here the server only sends a fit's packed
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
    (``COATED_JOB_CPU_LIMIT_S``; :class:`service.worker.JobCPULimit`, 422).
-   A job no request waits for any more (each timed out, or its client
    went away: :class:`service.api.middleware.RequestLimits` cancels the
    request) is cancelled: its worker checks every 0.1 s
    (:func:`service.worker.run_part`) and is free within a second. A
    preview's place is held until its worker is free, not only until its
    request ends, so the bound counts the work really running.
-   A worker that dies breaks the pool: it is replaced (its processes
    started again on the next job), and the jobs it held answer
    :class:`RenderWorkerLost`; a render is not tried again (one that killed
    its worker would kill the next).
"""

from __future__ import annotations

import asyncio
import collections
import concurrent.futures
import logging
import math
import multiprocessing
import threading
import time
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable

from .pool import FitTimeout, Overloaded, WorkerLost
from .render_worker import RendererUnavailable, render_worker_start
from .worker import CANCEL_SLOTS, run_part

__all__ = ["PreviewRunner", "PreviewsBusy", "PreviewTimeout", "RenderWorkerLost", "RendererUnavailable",
           "TEXTURE_QUEUE"]

log = logging.getLogger("service.previews")

TEXTURE_QUEUE = 16
"""Texture jobs in flight (running or waiting for a render process) at most; past it 503."""


class PreviewsBusy(Overloaded):
    """Previews (or textures) in flight at the bound; ``retry_after`` in seconds (503)."""

    def __init__(self, retry_after: int, what: str) -> None:
        Exception.__init__(self, f"{what}; retry in about {retry_after} s")
        self.retry_after = retry_after


class PreviewTimeout(FitTimeout):
    """A render request waited past its time limit (504); its job was cancelled."""

    def __init__(self, limit_s: float) -> None:
        Exception.__init__(
            self, f"the preview did not finish within the time limit of {limit_s:g} s "
                  "(COATED_PREVIEW_TIMEOUT_S); it was cancelled: ask for a smaller `size`")
        self.retry_after = max(1, math.ceil(limit_s / 4))


class RenderWorkerLost(WorkerLost):
    """The render process of a job died (503); the pool was replaced."""

    def __init__(self) -> None:
        Exception.__init__(self, "the render process of this preview died; the render pool was restarted")
        self.retry_after = 1


class PreviewRunner:
    """
    The render pool (see the module docstring).

    :meth:`preview` and :meth:`texture` run ``function(*args)`` in a render
    process (``function`` module-level, so that it pickles: the jobs of
    :mod:`service.jobs.previews` and :mod:`service.jobs.textures`) and return its result; concurrent calls with the same
    ``key`` share one job. The processes start on the first job.
    """

    def __init__(self, workers: int, timeout_s: float, cpu_limit_s: float,
                 texture_queue: int = TEXTURE_QUEUE) -> None:
        if workers < 1:
            raise ValueError(f"`workers` must be >= 1, got {workers}")
        self.workers = workers
        self.timeout_s = timeout_s
        self.cpu_limit_s = cpu_limit_s
        self.texture_queue = texture_queue
        self._context = multiprocessing.get_context("spawn")
        self._cancelled = self._context.Array("q", [-1] * CANCEL_SLOTS, lock=False)
        self._cancel_next = 0
        self._serial = 0
        self._lock = threading.Lock()  # counts are released from the executor's thread
        self._pool: concurrent.futures.ProcessPoolExecutor | None = None
        self._counts = {"preview": 0, "texture": 0}
        self._running: dict[int, concurrent.futures.Future] = {}
        self._pending: dict[tuple, asyncio.Task] = {}
        self._waiters: collections.Counter[tuple] = collections.Counter()
        self._mean_s = 4.0  # running estimate of one preview's seconds, for Retry-After
        self.restarts = 0

    @property
    def previews_in_flight(self) -> int:
        """Previews whose render process is busy with them (or about to be)."""
        return self._counts["preview"]

    def _executor(self) -> concurrent.futures.ProcessPoolExecutor:
        with self._lock:
            if self._pool is None:
                self._pool = concurrent.futures.ProcessPoolExecutor(
                    max_workers=self.workers, mp_context=self._context,
                    initializer=render_worker_start, initargs=(self._cancelled,))
            return self._pool

    def _replace(self, broken: concurrent.futures.ProcessPoolExecutor) -> None:
        with self._lock:
            if self._pool is not broken:
                return  # another job saw the same break first
            self._pool = None
            self.restarts += 1
        broken.shutdown(wait=False, cancel_futures=True)
        log.warning("a render process died; the render pool was replaced")

    def _admit(self, what: str) -> None:
        """Take a place of ``what`` ("preview" | "texture") or refuse (:class:`PreviewsBusy`)."""
        limit = self.workers if what == "preview" else self.texture_queue
        with self._lock:
            if self._counts[what] >= limit:
                waves = math.ceil(max(self._counts["preview"], 1) / self.workers)
                retry = max(1, math.ceil(waves * self._mean_s))
                raise PreviewsBusy(retry, (
                    f"{limit} previews are being rendered (COATED_MAX_PREVIEWS_IN_FLIGHT)" if what == "preview"
                    else f"{limit} textures are waiting for a render process"))
            self._counts[what] += 1

    def _leave(self, what: str, started: float | None = None) -> None:
        with self._lock:
            self._counts[what] -= 1
            if started is not None and what == "preview":
                self._mean_s = 0.8 * self._mean_s + 0.2 * (time.perf_counter() - started)

    async def _job(self, what: str, function: Callable[..., Any], args: tuple, submitted: list) -> Any:
        """
        One job in a render process; its place is left when its process is
        free of it (before it was submitted: when its task ends, :meth:`_once`).
        """
        pool = self._executor()
        with self._lock:
            self._serial += 1
            serial = self._serial
        started = time.perf_counter()
        try:
            future = pool.submit(run_part, serial, self.cpu_limit_s, function, *args)
        except (BrokenProcessPool, RuntimeError):
            self._replace(pool)
            raise RenderWorkerLost() from None
        submitted.append(serial)
        self._running[serial] = future

        def done(f: concurrent.futures.Future) -> None:
            self._running.pop(serial, None)
            self._leave(what, None if f.cancelled() or f.exception() is not None else started)

        future.add_done_callback(done)
        try:
            return await asyncio.wrap_future(future)
        except BrokenProcessPool:
            self._replace(pool)
            raise RenderWorkerLost() from None
        except asyncio.CancelledError:
            self._cancel(serial, future)
            raise

    def _cancel(self, serial: int, future: concurrent.futures.Future) -> None:
        """Stop a job: dropped if still queued, else its process stops at its next check."""
        if future.cancel():
            return
        with self._lock:
            self._cancelled[self._cancel_next % CANCEL_SLOTS] = serial
            self._cancel_next += 1

    async def _once(self, what: str, key: tuple, function: Callable[..., Any], args: tuple) -> Any:
        """``function(*args)`` as one job shared by the calls with ``key``, within the time limit."""
        key = (what, *key)
        task = self._pending.get(key)
        if task is None:
            self._admit(what)
            submitted: list[int] = []
            task = asyncio.ensure_future(self._job(what, function, args, submitted))
            self._pending[key] = task

            def finished(t: asyncio.Task) -> None:
                self._pending.pop(key, None)
                if not submitted:  # cancelled or refused before its process had it
                    self._leave(what)

            task.add_done_callback(finished)
        self._waiters[key] += 1
        try:
            return await asyncio.wait_for(asyncio.shield(task), self.timeout_s)
        except asyncio.TimeoutError:
            raise PreviewTimeout(self.timeout_s) from None
        finally:
            self._waiters[key] -= 1
            if self._waiters[key] <= 0:
                del self._waiters[key]
                if not task.done():
                    task.cancel()

    async def preview(self, key: tuple, function: Callable[..., Any], *args: Any) -> Any:
        """
        A preview: refused at once past ``workers`` in flight.

        Raises
        ------
        PreviewsBusy, PreviewTimeout, RenderWorkerLost, RendererUnavailable, JobCPULimit, ValueError
        """
        return await self._once("preview", key, function, args)

    async def texture(self, key: tuple, function: Callable[..., Any], *args: Any) -> Any:
        """A texture: waits for a render process (at most :data:`TEXTURE_QUEUE` at once); as :meth:`preview`."""
        return await self._once("texture", key, function, args)

    def close(self) -> None:
        """Cancel what runs (each process stops at its next check) and stop the processes."""
        for task in list(self._pending.values()):
            task.cancel()
        with self._lock:
            pool, self._pool = self._pool, None
            for serial in list(self._running):
                self._cancelled[self._cancel_next % CANCEL_SLOTS] = serial
                self._cancel_next += 1
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)
