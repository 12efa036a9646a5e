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

    Each part also has a ``rank`` (:meth:`service.runtime.shares.Shares.rank`):
    interactive parts (saves, live steps) wait before every bulk part
    (reads, packs, scenes), and the bulk client that used least worker time
    goes first; cost orders parts of one rank. Bulk parts take at most
    ``n - 1`` general turns when ``n`` is 2 or more and no express turn, so
    a save never waits for another client's reads, packs or scenes to end.
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
    """``n`` turns in the workers, ``express`` more for cheap parts; the first part waiting (rank, cost) goes next."""

    def __init__(self, n: int, express: int = 0, express_cost_s: float = 0.1) -> None:
        if n < 1 or express < 0:
            raise ValueError(f"`n` must be >= 1 and `express` >= 0, got {n} and {express}")
        self.n, self.express, self.express_cost_s = n, express, float(express_cost_s)
        self.bulk_max = n - 1 if n > 1 else n  # general turns bulk parts may hold together
        self.running = 0  # general turns taken
        self.bulk_running = 0  # of which by bulk parts
        self.express_running = 0
        self._waiting: list[tuple[tuple, float, int, bool, asyncio.Future]] = []
        self._order = itertools.count()

    def _cheap(self, cost_s: float, bulk: bool) -> bool:
        return cost_s <= self.express_cost_s and not bulk

    @contextlib.asynccontextmanager
    async def turn(self, cost_s: float, rank: tuple = (0, 0.0)) -> AsyncIterator[None]:
        """Hold one turn while the part runs (``cost_s``: its estimated seconds; ``rank``: its order, lowest first)."""
        cost_s, bulk = float(cost_s), rank[0] > 0
        if self.running < self.n and self._may_enter(bulk):
            lane = self._take(GENERAL, bulk)
        elif self._cheap(cost_s, bulk) and self.express_running < self.express:
            lane = self._take(EXPRESS, bulk)
        else:
            future = asyncio.get_running_loop().create_future()
            heapq.heappush(self._waiting, (tuple(rank), cost_s, next(self._order), bulk, future))
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

    def _may_enter(self, bulk: bool) -> bool:
        """Whether a part may take a free general turn now: past no bound, and no waiting part may take it."""
        capped = self.bulk_running >= self.bulk_max
        if bulk and capped:
            return False
        # A general turn is free while parts wait only when the first is a bulk part at its bound.
        return not self._live_waiters() or (self._waiting[0][3] and capped)

    def _take(self, lane: str, bulk: bool) -> tuple[str, bool]:
        if lane == EXPRESS:
            self.express_running += 1
        else:
            self.running += 1
            self.bulk_running += bulk
        return lane, bulk

    def _live_waiters(self) -> bool:
        while self._waiting and self._waiting[0][-1].done():
            heapq.heappop(self._waiting)  # a cancelled waiter
        return bool(self._waiting)

    def _release(self, held: tuple[str, bool]) -> None:
        lane, bulk = held
        if lane == EXPRESS:
            self.express_running -= 1
        else:
            self.running -= 1
            self.bulk_running -= bulk
        # The first waiting part by rank and cost, if it may take this turn (an express turn only a cheap
        # interactive part, a general one a bulk part only below their bound).
        if self._live_waiters():
            _, cost_s, _, waiter_bulk, future = self._waiting[0]
            if lane == EXPRESS and not self._cheap(cost_s, waiter_bulk):
                return
            if lane == GENERAL and waiter_bulk and self.bulk_running >= self.bulk_max:
                return
            heapq.heappop(self._waiting)
            future.set_result(self._take(lane, waiter_bulk))
