"""
What a PostgreSQL store's pool is doing, for a call that waits for a
connection: whether the wait is a queue behind live work or a server that
went away (:class:`PoolWatch`), and the pool's connection class that tells
it of each connection the pool opens (:func:`watched_connections`).
"""

from __future__ import annotations

import threading
import time
from typing import Any

import psycopg

__all__ = ["PoolWatch", "QUICK_WAIT_S", "watched_connections"]

QUICK_WAIT_S = 0.25
"""
How long a call waits for a pooled connection before it asks whether the
pool is busy or the server went away (``PostgresStore._connection``): a
pool with a connection free answers at once, and a server that went away
refuses at once, so the first call after it did is a 503 in well under a
second instead of a wait of the pool timeout, which a load balancer's
health check would read as a hang.
"""


class PoolWatch:
    """
    The pool's connections in calls now (:meth:`lent`), its connection
    attempts in flight, when the server last answered a call or accepted a
    connection of the pool's (:meth:`answered`), and the pool's last
    refused attempt. Thread-safe.
    """

    def __init__(self, pool_max: int) -> None:
        self.pool_max = pool_max
        self._lock = threading.Lock()
        self._lent = 0
        self._opening = 0
        self._answered_at = -float("inf")
        self._refused: tuple[float, psycopg.OperationalError] | None = None

    def lent(self, step: int) -> None:
        """A pooled connection went into a call (``step`` +1) or came back (-1)."""
        with self._lock:
            self._lent += step

    def answered(self) -> None:
        """The server answered a call (or refused it: it is there)."""
        self._answered_at = time.monotonic()

    def attempt(self, step: int, refused: psycopg.OperationalError | None) -> None:
        """A connection attempt of the pool's began (``step`` +1) or ended (-1, ``refused`` or None)."""
        with self._lock:
            self._opening += step
            if step < 0:
                if refused is None:
                    self._answered_at = time.monotonic()
                else:
                    self._refused = (time.monotonic(), refused)

    def busy_since(self, asked: float) -> bool:
        """
        Whether a wait for a pooled connection that began at ``asked`` is a
        queue behind live work rather than a server that went away: another
        call (or a new connection of the pool's) heard from the server
        since, all ``pool_max`` connections are in calls now (a lent
        connection that loses its server fails its own call, which marks
        the store down), or the pool is opening a connection now (growing
        under load, slowly on a loaded machine; its outcome answers the
        question, as a plain connection's would). (The pool's own
        ``pool_size`` is no guide: it counts the connections it is still
        trying to open.)
        """
        return self._answered_at > asked or self._lent >= self.pool_max or self._opening > 0

    def refusal_since(self, asked: float) -> psycopg.OperationalError | None:
        """A copy (other calls may raise it at once) of the pool's refusal after ``asked``, if any."""
        refused = self._refused
        if refused is None or refused[0] <= asked:
            return None
        return type(refused[1])(*refused[1].args)


def watched_connections(handed: list[psycopg.Connection[Any]], watch: PoolWatch) -> type[psycopg.Connection[Any]]:
    """
    A connection class for the pool whose next ``connect`` hands over a
    connection from ``handed`` (opened before the pool) instead of opening
    one more; once ``handed`` is empty it connects as usual, telling
    ``watch`` of each attempt (:meth:`PoolWatch.attempt`).
    """

    class Watched(psycopg.Connection[Any]):
        @classmethod
        def connect(cls, conninfo: str = "", **kwargs: Any) -> Any:  # type: ignore[override]
            try:
                return handed.pop()
            except IndexError:
                pass
            watch.attempt(+1, None)
            try:
                connection = super().connect(conninfo, **kwargs)
            except psycopg.OperationalError as error:
                watch.attempt(-1, error)
                raise
            watch.attempt(-1, None)
            return connection

    return Watched
