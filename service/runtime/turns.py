"""
Turns in the fitting pool
=========================

-   :class:`Turns`: at most ``n`` parts of jobs in the workers at once; of
    the parts waiting, the cheapest (its estimated seconds, then its
    arrival) goes next, so that a 0.1 s library fit does not wait behind ten
    worst-case refits (:class:`service.runtime.pool.FitRunner`). Parts only wait
    here while they hold their job's slot, and the slots are bounded, so an
    expensive part waits at most behind that many cheaper ones.

    Cheapest-first alone still makes a cheap part wait for a running part
    to end (up to a worst-case refit's second, once for each of a job's
    parts in sequence). So ``express`` more turns are kept for cheap parts
    (estimated at most ``express_cost_s``): a library fit's parts or a
    live step start at once while every general turn runs an expensive
    part, in a worker process of its own (the pool has ``n + express``
    workers). An expensive part never takes an express turn, so the
    expensive work in flight stays ``n``.
"""

from __future__ import annotations

import asyncio
import contextlib
import heapq
import itertools
from typing import AsyncIterator

__all__ = ["Turns", "GENERAL", "EXPRESS"]

GENERAL, EXPRESS = "general", "express"


class Turns:
    """``n`` turns in the workers, ``express`` more for cheap parts; the cheapest waiting part takes the next one free."""

    def __init__(self, n: int, express: int = 0, express_cost_s: float = 0.1) -> None:
        if n < 1 or express < 0:
            raise ValueError(f"`n` must be >= 1 and `express` >= 0, got {n} and {express}")
        self.n, self.express, self.express_cost_s = n, express, float(express_cost_s)
        self.running = 0  # general turns taken
        self.express_running = 0
        self._waiting: list[tuple[float, int, asyncio.Future]] = []
        self._order = itertools.count()

    def _cheap(self, cost_s: float) -> bool:
        return cost_s <= self.express_cost_s

    @contextlib.asynccontextmanager
    async def turn(self, cost_s: float) -> AsyncIterator[None]:
        """Hold one turn while the part runs (``cost_s``: its estimated seconds)."""
        cost_s = float(cost_s)
        if self.running < self.n and not self._live_waiters():
            self.running += 1
            lane = GENERAL
        elif self._cheap(cost_s) and self.express_running < self.express:
            self.express_running += 1
            lane = EXPRESS
        else:
            future = asyncio.get_running_loop().create_future()
            heapq.heappush(self._waiting, (cost_s, next(self._order), future))
            try:
                lane = await future
            except asyncio.CancelledError:
                if future.done() and not future.cancelled():
                    self._release(future.result())  # the turn came with the cancellation: passed on
                future.cancel()
                raise
        try:
            yield
        finally:
            self._release(lane)

    def _live_waiters(self) -> bool:
        while self._waiting and self._waiting[0][2].done():
            heapq.heappop(self._waiting)  # a cancelled waiter
        return bool(self._waiting)

    def _release(self, lane: str) -> None:
        # The cheapest waiting part first; an express turn only to a cheap one.
        while self._live_waiters():
            cost_s, _, future = self._waiting[0]
            if lane == EXPRESS and not self._cheap(cost_s):
                break
            heapq.heappop(self._waiting)
            future.set_result(lane)
            return
        if lane == EXPRESS:
            self.express_running -= 1
        else:
            self.running -= 1
