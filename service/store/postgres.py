"""
The PostgreSQL store
====================

:class:`PostgresStore`: the :class:`service.store.Store` on a PostgreSQL
server shared by any number of service replicas, through a bounded psycopg
3 connection pool per replica. The tables, the version numbers of the
schema and every query are those of the SQLite store
(:mod:`service.store.migrations`, :mod:`service.store.queries`).

-   Records are the same JSON text as in SQLite (``record TEXT``): a move
    from SQLite is byte for byte (its checksum compares the texts), and JSON
    that ``JSONB`` refuses (a ``\\u0000`` in a name) stays storable.
-   Every save takes one transaction-scoped advisory lock
    (:data:`SAVE_LOCK`), so saves from all replicas are serialised as
    SQLite's are: the save log's ``seq`` grows in commit order (a page
    cursor never skips a save that committed late), a material's latest
    fit is the one saved last, and the expected-version check of
    ``put_fit`` cannot race. A save holds the lock for a few milliseconds;
    the fitting, the expensive part, is outside it.
-   A commit returns after PostgreSQL has flushed it (``synchronous_commit``
    as the server has it, on by default): an answered save survives the
    replica and the server.
-   Connection faults (the server restarting, unreachable, every pooled
    connection busy past ``pool_timeout_s``) leave as
    :class:`StoreUnavailable` with ``retry_after`` of a few seconds (503 +
    Retry-After); a pooled connection is checked before use, so after a
    server restart the pool reconnects by itself (within about a second;
    a failed reconnection is given up after ``2 * pool_timeout_s`` and
    tried afresh on the next call, so its back-off never grows long).
    While the server is down, calls fail at once (one plain connection
    attempt beside the pool at a time, which calls that come during it
    share: at most ``pool_max + 1`` connections, however many calls),
    the first one after it went away too: a call that gets no pooled
    connection within :data:`QUICK_WAIT_S` goes on waiting while the pool
    is busy (another call heard from the server since, every connection
    is in a call, or the pool is opening one), else takes the refusal of
    the pool's own attempt, else tries one plain connection (or shares the
    one in flight), whose refusal answers it, and otherwise waits the rest
    of ``pool_timeout_s``.
"""

from __future__ import annotations

import logging
import os
import socket
import time
from typing import Any, Callable, TypeVar

import psycopg
from psycopg import errors as pg_errors
from psycopg_pool import ConnectionPool, PoolTimeout

from . import queries, records
from .sql import SQLStore
from .migrations import SCHEMA_VERSION
from .migrations import migrate as _migrate
from .records import (
    FitRecord,
    StoreError,
    StoreFull,
    StoreUnavailable,
)
from .pool_watch import QUICK_WAIT_S, PoolWatch, watched_connections
from .shared_check import SharedCheck

__all__ = ["PostgresStore", "QUICK_WAIT_S", "SAVE_LOCK", "redacted"]

log = logging.getLogger("service.store")
_T = TypeVar("_T")

SAVE_LOCK = 0x636F617465645F73  # the advisory lock every save takes (pg_advisory_xact_lock)
RETRY_AFTER_S = 2
"""Retry-After of a 503 for a connection fault: the pool reconnects within a few seconds."""


def redacted(url: str) -> str:
    """``url`` without its password, for messages and ``/healthz``."""
    try:
        info = psycopg.conninfo.conninfo_to_dict(url)
    except psycopg.ProgrammingError:
        return "postgresql://(unparsable URL)"
    host, port, db = info.get("host", "localhost"), info.get("port", "5432"), info.get("dbname", "")
    user = info.get("user", "")
    return f"postgresql://{user + '@' if user else ''}{host}:{port}/{db}"


def _message(error: Exception) -> str:
    """libpq's message on one line (it spreads a refusal over several)."""
    return " ".join(str(error).split())


def _translate(error: Exception, where: str) -> StoreError:
    """A psycopg or pool error as the store error it means."""
    if isinstance(error, PoolTimeout):
        return StoreUnavailable(
            f"the store at {where} is unavailable: no database connection within the pool timeout "
            f"(COATED_STORE_POOL_TIMEOUT_S; all COATED_STORE_POOL_MAX connections busy, or the server "
            f"is down): {_message(error)}",
            retry_after=RETRY_AFTER_S,
        )
    if isinstance(error, pg_errors.DiskFull):
        return StoreFull(
            f"the store at {where} is full ({_message(error)}): free disk space on the database "
            "server or raise COATED_STORE_MAX_BYTES, then retry"
        )
    if isinstance(error, pg_errors.TooManyConnections):
        return StoreUnavailable(
            f"the store at {where} refused a connection ({_message(error)}): the replicas' connections exceed "
            "the role's CONNECTION LIMIT or the server's max_connections (docs/deploy.md)",
            retry_after=RETRY_AFTER_S,
        )
    return StoreUnavailable(f"the store at {where} is unavailable: {_message(error)}", retry_after=RETRY_AFTER_S)


class PostgresStore(SQLStore):
    """
    :class:`Store` on PostgreSQL at ``url`` (``postgresql://user:password@host:port/db``).

    ``pool_min`` / ``pool_max`` bound the connections this process opens
    (each replica's share of the server's connections, see
    ``docs/deploy.md``); a call waits at most ``pool_timeout_s`` for one
    (then 503). ``statement_timeout_s`` bounds every statement on the
    server. ``max_bytes`` is a quota of the database
    (``pg_database_size``); a save past it is refused 507 before fitting.
    The schema is migrated on opening unless ``migrate`` is False (then a
    schema other than :data:`SCHEMA_VERSION` is refused).
    """

    kind = "postgresql"
    placeholder = "%s"

    def __init__(
        self,
        url: str,
        pool_min: int = 1,
        pool_max: int = 4,
        pool_timeout_s: float = 5.0,
        statement_timeout_s: float = 30.0,
        connect_timeout_s: float = 5.0,
        max_bytes: int | None = None,
        migrate: bool = True,
    ) -> None:
        self.where = redacted(url)
        self._url, self._down = url, False
        self._watch = PoolWatch(pool_max)
        self._pool_timeout_s = float(pool_timeout_s)
        self._connect_timeout = max(1, int(connect_timeout_s))
        # One plain connection at a time beside the pool (at most pool_max + 1), shared by concurrent calls.
        self._probe = SharedCheck(self._connect_once, psycopg.OperationalError, self._connect_timeout + 1.0)
        self.max_bytes = max_bytes
        self.pool_max = pool_max
        name = f"coated-service {socket.gethostname()}:{os.getpid()}"[:63]
        options = (
            f"-c statement_timeout={int(statement_timeout_s * 1000)} -c lock_timeout={int(statement_timeout_s * 1000)}"
        )
        connect_kwargs = {"application_name": name, "connect_timeout": self._connect_timeout, "options": options}
        handed: list[psycopg.Connection[Any]] = []
        self._pool = ConnectionPool(
            url,
            connection_class=watched_connections(handed, self._watch),
            min_size=pool_min,
            max_size=pool_max,
            timeout=pool_timeout_s,
            open=False,
            check=ConnectionPool.check_connection,
            reconnect_timeout=2 * pool_timeout_s,
            max_waiting=256,
            kwargs=connect_kwargs,
            name="coated-store",
        )
        try:
            # One plain connection first: its refusal is the server's own message (the pool's is a timeout).
            # It is then the pool's first connection, not closed beside it: a server counts a closed
            # connection until its backend has exited, so a replica at the role's CONNECTION LIMIT
            # would otherwise be refused its own last connection at start-up.
            handed.append(psycopg.Connection.connect(url, **connect_kwargs))
            self._pool.open(wait=True, timeout=connect_timeout_s + pool_timeout_s)
        except (PoolTimeout, psycopg.Error) as error:
            if "too many connections" in str(error):
                error = psycopg.OperationalError(
                    f"{_message(error)}: this replica's COATED_STORE_POOL_MIN connections exceed what "
                    "the role's CONNECTION LIMIT or max_connections leaves (docs/deploy.md)"
                )
            self._pool.close(timeout=1.0)
            for connection in handed:
                connection.close()
            raise StoreUnavailable(f"the store at {self.where} cannot be reached: {_message(error)}") from None
        try:
            self.migrated = self._guard(lambda: self._run(lambda c: _migrate(c, "postgresql", migrate)))
            self.role_limit, self.server_limit = self._read(
                lambda c: c.execute(
                    "SELECT (SELECT rolconnlimit FROM pg_roles WHERE rolname = current_user), "
                    "current_setting('max_connections')::int - current_setting('superuser_reserved_connections')::int"
                ).fetchone()
            )
        except StoreError:
            self._pool.close(timeout=1.0)
            raise
        if self.role_limit < 0:
            log.warning(
                "the role of %s has no CONNECTION LIMIT: N replicas may take up to the server's "
                "%d connections (docs/deploy.md)",
                self.where,
                self.server_limit,
            )

    # -- plumbing ----------------------------------------------------------

    def _guard(self, function: Callable[[], _T]) -> _T:
        try:
            return function()
        except (psycopg.Error, PoolTimeout) as error:
            raise _translate(error, self.where) from None

    def _run(self, function: Callable[[psycopg.Connection], _T]) -> _T:
        """
        ``function`` on a pooled connection, one transaction (rolled back on
        error). After a connection fault, each call first tries one plain
        connection (refused at once while the server is down, so a 503 is
        quick instead of a wait of ``pool_timeout_s``) until one succeeds;
        a call that waits past :data:`QUICK_WAIT_S` for a pooled one
        while the pool is not busy asks the server too (:meth:`_connection`).
        """
        if self._down:
            self._probe()
        try:
            connection = self._connection()
        except PoolTimeout:
            self._probe()  # the server's own refusal when it is down; else the pool is busy
            raise
        except psycopg.OperationalError:
            self._down = True
            raise
        self._watch.lent(+1)
        try:
            with connection:  # commit, or roll back on an error (the pool keeps the connection open)
                result = function(connection)
            self._watch.answered()
            return result
        except psycopg.OperationalError:
            self._down = True
            raise
        except psycopg.Error:
            self._watch.answered()  # the server's own refusal: it is there
            raise
        finally:
            self._watch.lent(-1)
            self._pool.putconn(connection)

    def _connection(self) -> psycopg.Connection:
        """
        A pooled connection within ``pool_timeout_s``, waited for in steps
        of :data:`QUICK_WAIT_S`. While the pool is busy with live work
        (:meth:`PoolWatch.busy_since`) the wait goes on; else a connection
        attempt of the pool's that the server refused since the call asked
        raises that refusal at once; else one plain connection (or the one
        another call is making, :attr:`_probe`) asks the server, whose
        refusal raises at once, and the call then waits the rest.
        """
        asked = time.monotonic()
        deadline = asked + self._pool_timeout_s
        while True:
            try:
                return self._pool.getconn(timeout=max(0.0, min(QUICK_WAIT_S, deadline - time.monotonic())))
            except PoolTimeout:
                if time.monotonic() >= deadline:
                    raise
            if self._watch.busy_since(asked):
                continue
            refused = self._watch.refusal_since(asked)
            if refused is not None:
                raise refused
            break
        self._probe()
        return self._pool.getconn(timeout=max(0.0, deadline - time.monotonic()))

    def _connect_once(self) -> None:
        """
        One plain connection (through :attr:`_probe`, one at a time, which
        the calls that come during it share): raises
        ``psycopg.OperationalError`` (and marks the server down) when the
        server refuses it.
        """
        try:
            psycopg.connect(self._url, connect_timeout=self._connect_timeout).close()
        except psycopg.OperationalError:
            self._down = True
            raise
        self._down = False

    def _read(self, function: Callable[[psycopg.Connection], _T]) -> _T:
        return self._guard(lambda: self._run(function))

    def transaction(self, function: Callable[[psycopg.Connection], _T]) -> _T:
        """``function(connection)`` in one transaction on a pooled connection; errors as :class:`StoreError`."""
        return self._read(function)

    # -- the interface -----------------------------------------------------

    def put_fit(
        self,
        record: FitRecord,
        save: bool = True,
        expected_version: int | None = None,
        nk: dict[str, list[float]] | None = None,
    ) -> FitRecord:
        record, text, nk_json = records.prepared(record, nk)

        def write(connection: psycopg.Connection) -> FitRecord:
            if save or nk_json is not None:
                # With an n, k record: the sweep must not find it unreferenced
                # between this insert and the draft's (it takes the same lock).
                connection.execute("SELECT pg_advisory_xact_lock(%s)", (SAVE_LOCK,))
            return queries.save(connection, "%s", record, text, save, expected_version, self._decode, nk_json)

        return self._read(write)

    def _write(self, function: Callable[[psycopg.Connection], _T]) -> _T:
        """``function(connection)`` in one transaction holding the saves' advisory lock."""

        def write(connection: psycopg.Connection) -> _T:
            connection.execute("SELECT pg_advisory_xact_lock(%s)", (SAVE_LOCK,))
            return function(connection)

        return self._read(write)

    def check(self) -> None:
        """The server answers and the schema is this code's (PostgreSQL checks its own pages)."""
        (version,) = self._read(
            lambda c: c.execute("SELECT COALESCE(MAX(version), 0) FROM schema_migrations").fetchone()
        )
        if version != SCHEMA_VERSION:
            raise StoreUnavailable(
                f"the store at {self.where} has schema version {version}, this code needs {SCHEMA_VERSION}"
            )

    def ping(self) -> None:
        self._read(lambda c: c.execute("SELECT 1 FROM saves LIMIT 1").fetchall())

    def describe(self) -> dict[str, Any]:
        stats = self._pool.get_stats()
        return {
            "kind": self.kind,
            "schema_version": SCHEMA_VERSION,
            "url": self.where,
            "connections": stats.get("pool_size", 0),
            "connections_max": self.pool_max,
            "connections_idle": stats.get("pool_available", 0),
            "requests_waiting": stats.get("requests_waiting", 0),
            "role_connection_limit": self.role_limit,
            "server_connection_limit": self.server_limit,
        }

    def writable(self) -> str | None:
        def probe(connection: psycopg.Connection) -> str | None:
            (read_only,) = connection.execute("SHOW transaction_read_only").fetchone()
            if read_only == "on":
                return f"the store at {self.where} is read-only (a standby, or default_transaction_read_only)"
            if self.max_bytes:
                (size,) = connection.execute("SELECT pg_database_size(current_database())").fetchone()
                if size >= self.max_bytes:
                    return f"the store holds {size} bytes, at its quota COATED_STORE_MAX_BYTES ({self.max_bytes})"
            return None

        # A server that cannot be reached raises (503 + Retry-After), as every other call does.
        return self._read(probe)

    def close(self) -> None:
        self._pool.close(timeout=5.0)
