"""
Connection admission
====================

The bookkeeping of :class:`service.runtime.server.DeadlineH11Protocol`'s
bounds, without uvicorn: :class:`Admission` keeps a server's connections in
the order of their last activity (least recent first), all together and by
client address, and apart from them the connections admitted for
``/healthz`` alone (the reserve, :data:`HEALTH_RESERVE`).

A connection counts as idle (:meth:`Admission.evict` may close it) when it
has no request in progress, or when its request's body is arriving slower
than the minimum rate: a slow body holds its place no better than an idle
connection does. The reserve is never closed for an ordinary connection;
each of its connections must send its request within :data:`IDLE_GRACE_S`,
and past its own bound the oldest connection of the address holding most
of it that has not sent its request yet is closed, so an address flooding
the reserve shuts out its own probes first.

:meth:`Admission.held` says whether every connection the server accepts is
busy (``/healthz`` answers 503 then: a load balancer should send new
clients elsewhere).
"""

from __future__ import annotations

from typing import Protocol

__all__ = ["Admission", "HEALTH_RESERVE", "IDLE_GRACE_S", "BODY_GRACE_S"]

HEALTH_RESERVE = 256
"""Connections past the bounds admitted at once (for ``/healthz``, any other request answered 503): past
it the address holding most of them loses its oldest that has not sent its request yet."""
IDLE_GRACE_S = 1.0
"""How long after its last byte a connection is not yet counted idle by the
per-address bound: a new connection's first request, or a keep-alive
connection's next one, may be on its way (a round trip or two on a slow
network); a connection admitted for ``/healthz`` alone must send its
request within it."""
BODY_GRACE_S = 2.0
"""After its header, the time a request body has before the minimum rate
applies: it must have sent ``rate x (elapsed - BODY_GRACE_S)`` bytes at any
time (the rule of Apache's ``mod_reqtimeout``, ``MinRate``)."""


class Connection(Protocol):
    """What :class:`Admission` asks of a connection."""

    host: str | None
    last_active: float
    served: bool

    def idle(self) -> bool: ...

    def waiting(self) -> bool: ...

    def close(self) -> None: ...


class Admission:
    """The connections of one server, by their last activity; see the module's description."""

    def __init__(self, max_connections: int, max_per_client: int) -> None:
        self.max_connections = max_connections
        self.max_per_client = max_per_client
        self.everyone: dict[Connection, None] = {}
        self.by_host: dict[str | None, dict[Connection, None]] = {}
        self.reserve: dict[Connection, None] = {}
        self.reserve_by_host: dict[str | None, dict[Connection, None]] = {}

    @staticmethod
    def _put(order: dict, groups: dict, connection: Connection) -> None:
        for each in (order, groups.setdefault(connection.host, {})):
            each.pop(connection, None)
            each[connection] = None

    @staticmethod
    def _drop(order: dict, groups: dict, connection: Connection) -> None:
        order.pop(connection, None)
        mine = groups.get(connection.host)
        if mine is not None:
            mine.pop(connection, None)
            if not mine:
                del groups[connection.host]

    def touch(self, connection: Connection, reserved: bool = False) -> None:
        """Put ``connection`` last (the most recently active), in the reserve or among the others."""
        if reserved:
            self._put(self.reserve, self.reserve_by_host, connection)
        else:
            self._put(self.everyone, self.by_host, connection)

    def discard(self, connection: Connection) -> None:
        self._drop(self.everyone, self.by_host, connection)
        self._drop(self.reserve, self.reserve_by_host, connection)

    def admit(self, connection: Connection, now: float) -> bool:
        """
        Admit a new ``connection`` (already :meth:`touch`-ed): True when it is
        within the bounds (closing an idle one where needed), False when it is
        past them with none idle: it then moves to the reserve, for
        ``/healthz`` alone, whose own bounds close a silent one past them.
        """
        mine = self.by_host[connection.host]
        within = True
        if connection.host is not None and len(mine) > self.max_per_client:
            within = self.evict(mine, connection, now)
        # The service's own bound gives way to any idle connection, however new: it keeps /healthz's slots.
        elif len(self.everyone) > self.max_connections:
            within = self.evict(self.everyone, connection, now, grace=False)
        if not within:
            self._drop(self.everyone, self.by_host, connection)
            self.touch(connection, reserved=True)
            if len(self.reserve) > HEALTH_RESERVE:
                self._close_first_waiting(max(self.reserve_by_host.values(), key=len))
        return within

    def _close_first_waiting(self, candidates: dict) -> None:
        for other in candidates:
            if other.waiting():
                self.discard(other)
                other.close()
                return

    def evict(self, candidates: dict, newcomer: Connection, now: float, grace: bool = True) -> bool:
        """
        Close the longest idle connection of ``candidates`` (not
        ``newcomer``; with ``grace`` only one silent for
        :data:`IDLE_GRACE_S`; without, any but a connection that has answered
        a request within it); False when none is. ``candidates`` are in the
        order of their last activity, so the search stops at the first idle
        one, or (with ``grace``) at the first active within the grace: a
        flood costs each new connection a few steps, not a pass over every
        connection.
        """
        for other in candidates:
            recent = now - other.last_active < IDLE_GRACE_S
            if grace and recent:
                return False  # the rest were active more recently still
            if recent and other.served:
                continue  # a keep-alive connection just answered: its next request may be on its way
            if other is not newcomer and other.idle():
                self.discard(other)
                other.close()
                return True
        return False

    def held(self) -> str | None:
        """Why a new connection could not be served now (every one accepted is busy), or None."""
        if len(self.everyone) < self.max_connections or any(c.idle() for c in self.everyone):
            return None
        return (
            f"all {self.max_connections} connections this replica accepts have a request in progress "
            "(COATED_MAX_CONNECTIONS)"
        )
