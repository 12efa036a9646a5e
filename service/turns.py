"""
Turns in the fitting pool
=========================

-   :class:`Turns`: at most ``n`` parts of jobs in the workers at once; of
    the parts waiting, the cheapest (its estimated seconds, then its
    arrival) goes next, so that a 0.1 s library fit does not wait behind ten
    worst-case refits (:class:`service.pool.FitRunner`). Parts only wait
    here while they hold their job's slot, and the slots are bounded, so an
    expensive part waits at most behind that many cheaper ones.
"""

from __future__ import annotations

import asyncio
import contextlib
import heapq
import itertools
from typing import AsyncIterator

__all__ = ["Turns"]


class Turns:
    """``n`` turns in the workers; the cheapest waiting part takes the next one free."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.running = 0
        self._waiting: list[tuple[float, int, asyncio.Future]] = []
        self._order = itertools.count()

    @contextlib.asynccontextmanager
    async def turn(self, cost_s: float) -> AsyncIterator[None]:
        """Hold one turn while the part runs (``cost_s``: its estimated seconds)."""
        if self.running < self.n and not self._waiting:
            self.running += 1
        else:
            future = asyncio.get_running_loop().create_future()
            heapq.heappush(self._waiting, (float(cost_s), next(self._order), future))
            try:
                await future
            except asyncio.CancelledError:
                if future.done() and not future.cancelled():
                    self._release()  # the turn came with the cancellation: passed on
                future.cancel()
                raise
        try:
            yield
        finally:
            self._release()

    def _release(self) -> None:
        while self._waiting:
            _, _, future = heapq.heappop(self._waiting)
            if not future.done():  # a cancelled waiter is skipped
                future.set_result(None)
                return
        self.running -= 1
