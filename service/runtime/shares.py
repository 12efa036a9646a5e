"""
Fair shares of the fitting pool
===============================

One bound on the jobs in flight, shared by everyone, let the cheapest
requests of one client (token-less reads, packs, scenes) hold every slot
and every worker while the writers waited or got 503. The pool
(:class:`service.pool.FitRunner`) now knows whose work each job is:

-   :class:`Claim`: who asks (``client``: ``"token"`` when the request
    carries the service's token, else its address) and the kind of work
    (:data:`KINDS`). ``save`` (fits, uploads, the editor's saves and live
    steps) is interactive; ``scene``, ``pack`` and ``read`` (exports and
    other downloads computed on demand) are bulk.
-   :data:`CLAIM`: the claim of the request a job runs for (a context
    variable set by :class:`service.api.middleware.ClaimWork`; the jobs
    started in the request inherit it).
-   :class:`Shares`: admission and accounting. Bulk jobs may hold at most
    ``max_in_flight - reserved`` slots together and ``per_client`` each
    client, and one client's bulk jobs at most ``client_cost_s`` of
    estimated CPU seconds together (a scene of 64 x 32 counts its 2,048
    parts, not one job; a client's first job is always admitted by cost);
    past any of these the request is answered 503 with ``Retry-After``
    (:class:`ShareExceeded`) while the other clients and every interactive
    request keep theirs. Worker time is charged per client and per kind
    (``charge``); it decays with a half-life of :data:`HALF_LIFE_S`, and a
    bulk client's waiting parts are ordered by it (:meth:`Shares.rank`),
    so the client that used least goes first.
-   :class:`SaveRate`: saves (new versions) per client per minute, at
    most ``per_minute``; past it :class:`TooManySaves` (429 with
    ``Retry-After``).

The turns in the workers (:class:`service.turns.Turns`) put every waiting
interactive part before every bulk one, and keep one general worker of
two or more for interactive parts.
"""

from __future__ import annotations

import collections
import contextvars
import math
import threading
import time
from dataclasses import dataclass

__all__ = [
    "Claim",
    "CLAIM",
    "KINDS",
    "INTERACTIVE",
    "Shares",
    "ShareExceeded",
    "HALF_LIFE_S",
    "SaveRate",
    "TooManySaves",
]

KINDS = ("save", "scene", "pack", "read")
"""The kinds of work, as the pool accounts them."""

INTERACTIVE = frozenset({"save"})
"""The kinds whose parts go before every bulk part and whose slots are reserved."""

HALF_LIFE_S = 60.0
"""How fast a client's charged worker time is forgotten."""

_CLIENTS_KEPT = 4096  # clients whose standing is remembered at most (the least charged go first)


@dataclass(frozen=True)
class Claim:
    """Whose work a job is (``client``) and its kind (one of :data:`KINDS`)."""

    client: str
    kind: str

    @property
    def interactive(self) -> bool:
        return self.kind in INTERACTIVE


CLAIM: contextvars.ContextVar[Claim] = contextvars.ContextVar("claim", default=Claim("local", "save"))  # noqa: B039 (Claim is frozen)
"""The running request's claim; work started outside a request (warm-up, tests) is the service's own."""


class ShareExceeded(Exception):
    """A bulk request past its client's share or the bulk share of the pool (503, ``retry_after`` s)."""

    def __init__(self, retry_after: int, message: str) -> None:
        super().__init__(message)
        self.retry_after = retry_after


class Shares:
    """
    Admission of bulk jobs and worker time charged per client and kind.

    ``max_in_flight``: the pool's bound on jobs in flight; ``reserved`` of
    it are kept for interactive jobs; ``per_client``: bulk jobs of one
    client in flight at most; ``client_cost_s``: their estimated CPU
    seconds together at most (None: no bound). Thread-safe.
    """

    def __init__(self, max_in_flight: int, reserved: int, per_client: int, client_cost_s: float | None = None) -> None:
        if not 0 <= reserved < max_in_flight or per_client < 1:
            raise ValueError(
                f"`reserved` ({reserved}) must lie in [0, {max_in_flight}) and `per_client` ({per_client}) be >= 1"
            )
        self.bulk_max = max_in_flight - reserved
        self.per_client = per_client
        self.client_cost_s = client_cost_s
        self._lock = threading.Lock()
        self._bulk = 0
        self._bulk_by_client: dict[str, int] = {}
        self._cost_by_client: dict[str, float] = {}
        self._standing: dict[str, tuple[float, float]] = {}  # client -> (charged s, as of monotonic time)
        self.charged_by_kind = dict.fromkeys(KINDS, 0.0)
        """Worker seconds charged to each kind since the start."""

    def admit(self, claim: Claim, retry_after: int, cost_s: float = 0.0) -> None:
        """
        Take a bulk slot for ``claim`` (an interactive claim takes none), a
        job of ``cost_s`` estimated CPU seconds; :class:`ShareExceeded` past a share.
        """
        if claim.interactive:
            return
        with self._lock:
            held = self._bulk_by_client.get(claim.client, 0)
            if held >= self.per_client:
                raise ShareExceeded(
                    retry_after,
                    (
                        f"this client has {held} {claim.kind} jobs in flight, its share of the fitting pool "
                        f"(COATED_CLIENT_BULK_JOBS); retry in about {retry_after} s"
                    ),
                )
            cost = self._cost_by_client.get(claim.client, 0.0)
            if self.client_cost_s is not None and held and cost + cost_s > self.client_cost_s:
                raise ShareExceeded(
                    retry_after,
                    (
                        f"this client's jobs in flight are estimated at {cost:.1f} s of fitting; with this "
                        f"{claim.kind} job's {cost_s:.1f} s they would pass its share, {self.client_cost_s:g} s "
                        f"(COATED_FIT_TIMEOUT_S x COATED_FIT_WORKERS); retry in about {retry_after} s"
                    ),
                )
            if self._bulk >= self.bulk_max:
                raise ShareExceeded(
                    retry_after,
                    (
                        f"the fitting pool runs {self._bulk} reads, packs and scenes, their share (the rest is kept "
                        f"for saves); retry in about {retry_after} s"
                    ),
                )
            self._bulk += 1
            self._bulk_by_client[claim.client] = held + 1
            self._cost_by_client[claim.client] = cost + cost_s

    def leave(self, claim: Claim, cost_s: float = 0.0) -> None:
        """Give back the slot :meth:`admit` took (for a job of ``cost_s``)."""
        if claim.interactive:
            return
        with self._lock:
            self._bulk -= 1
            left = self._bulk_by_client.pop(claim.client) - 1
            cost = self._cost_by_client.pop(claim.client) - cost_s
            if left:
                self._bulk_by_client[claim.client] = left
                self._cost_by_client[claim.client] = max(0.0, cost)

    def charge(self, claim: Claim, seconds: float) -> None:
        """Charge ``seconds`` of a worker's time to ``claim``'s client and kind."""
        now = time.monotonic()
        with self._lock:
            self.charged_by_kind[claim.kind] = self.charged_by_kind.get(claim.kind, 0.0) + seconds
            self._standing[claim.client] = (self._decayed(claim.client, now) + seconds, now)
            if len(self._standing) > _CLIENTS_KEPT:
                least = min(self._standing, key=lambda c: self._decayed(c, now))
                del self._standing[least]

    def _decayed(self, client: str, now: float) -> float:
        charged, at = self._standing.get(client, (0.0, now))
        return charged * math.exp2(-(now - at) / HALF_LIFE_S)

    def standing(self, client: str) -> float:
        """``client``'s charged worker seconds, decayed (half-life :data:`HALF_LIFE_S`)."""
        with self._lock:
            return self._decayed(client, time.monotonic())

    def rank(self, claim: Claim) -> tuple[int, float]:
        """The order of a waiting part: interactive first, then the bulk client that used least."""
        return (0, 0.0) if claim.interactive else (1, self.standing(claim.client))

    def bulk_in_flight(self) -> int:
        with self._lock:
            return self._bulk


class TooManySaves(Exception):
    """A client past its saves per minute (429, ``retry_after`` s)."""

    def __init__(self, retry_after: int, message: str) -> None:
        super().__init__(message)
        self.retry_after = retry_after


class SaveRate:
    """
    At most ``per_minute`` saves of one client (:class:`Claim` ``client``)
    in any 60 s, counted in this process (a replica's own). Thread-safe.
    """

    def __init__(self, per_minute: int) -> None:
        if per_minute < 1:
            raise ValueError(f"`per_minute` must be >= 1, got {per_minute}")
        self.per_minute = per_minute
        self._lock = threading.Lock()
        self._times: dict[str, collections.deque] = {}

    def note(self, claim: Claim) -> None:
        """Count one save of ``claim``'s client now, or raise :class:`TooManySaves` past the rate."""
        now = time.monotonic()
        with self._lock:
            times = self._times.setdefault(claim.client, collections.deque())
            while times and times[0] <= now - 60.0:
                times.popleft()
            if len(times) >= self.per_minute:
                wait = max(1, math.ceil(times[0] + 60.0 - now))
                raise TooManySaves(
                    wait,
                    (
                        f"this client saved {len(times)} times in the last minute, the most it may "
                        f"(COATED_SAVES_PER_CLIENT_PER_MINUTE); retry in about {wait} s"
                    ),
                )
            times.append(now)
            if len(self._times) > _CLIENTS_KEPT:  # forget the clients whose window has ended
                for client in [c for c, t in self._times.items() if not t or t[-1] <= now - 60.0]:
                    del self._times[client]
