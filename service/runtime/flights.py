"""
Shared flights and cancellation
===============================

What the fitting pool (:class:`service.runtime.pool.FitRunner`) and the render pool
(:class:`service.runtime.previews.PreviewRunner`) both need of a job:

-   :class:`Flights`: one flight per key. Concurrent requests for the same
    content share one task; each waits at most its time limit; a task no
    request waits for any more (each timed out, or its client went away) is
    cancelled.
-   :class:`CancelRing`: the serials of cancelled jobs, in a ring of
    :data:`service.runtime.worker.CANCEL_SLOTS` shared with the worker processes,
    which stop a cancelled job at its next check.
"""

from __future__ import annotations

import asyncio
import collections
import concurrent.futures
import threading
from collections.abc import Hashable
from typing import Any, Callable

from .worker import CANCEL_SLOTS

__all__ = ["Flights", "CancelRing"]


class Flights:
    """The tasks in flight by key, and how many requests wait for each."""

    def __init__(self) -> None:
        self.pending: dict[Hashable, asyncio.Task] = {}
        self._waiters: collections.Counter[Hashable] = collections.Counter()

    def start(self, key: Hashable, make: Callable[[], asyncio.Task]) -> asyncio.Task:
        """The task in flight for ``key``, else ``make()``'s (forgotten when it ends)."""
        task = self.pending.get(key)
        if task is None:
            task = self.pending[key] = make()
            task.add_done_callback(lambda t: self.pending.pop(key, None))
        return task

    async def join(
        self, key: Hashable, task: asyncio.Task, timeout_s: float, timed_out: Callable[[], BaseException]
    ) -> Any:
        """
        ``task``'s result within ``timeout_s`` seconds, else ``timed_out()``
        raised; the last request to stop waiting for an unfinished task
        cancels it.
        """
        self._waiters[key] += 1
        try:
            return await asyncio.wait_for(asyncio.shield(task), timeout_s)
        except asyncio.TimeoutError:
            raise timed_out() from None
        finally:
            self._waiters[key] -= 1
            if self._waiters[key] <= 0:
                del self._waiters[key]
                if not task.done():
                    task.cancel()

    def cancel_all(self) -> None:
        for task in list(self.pending.values()):
            task.cancel()


class CancelRing:
    """Serials of cancelled jobs, shared with the worker processes (``shared``, their initializer's argument)."""

    def __init__(self, context) -> None:
        self.shared = context.Array("q", [-1] * CANCEL_SLOTS, lock=False)
        self._next = 0
        self._lock = threading.Lock()

    def cancel(self, serial: int, future: concurrent.futures.Future) -> None:
        """Stop a job: dropped if still queued, else its process stops at its next check."""
        if future.cancel():
            return
        with self._lock:
            self.shared[self._next % CANCEL_SLOTS] = serial
            self._next += 1
