"""
The SQLite store
================

:class:`SQLiteStore`: the :class:`service.store.Store` on one SQLite file in
WAL mode (see the package docstring for what is kept and how).
"""

from __future__ import annotations

import logging
import os
import sqlite3
import contextlib
import threading
from pathlib import Path
from typing import Any, Callable, TypeVar

from . import queries, records
from .sql import SQLStore
from .migrations import SCHEMA_VERSION
from .migrations import migrate as _migrate
from .records import (
    FitRecord,
    StoreDamaged,
    StoreError,
    StoreFull,
    StoreUnavailable,
)

log = logging.getLogger("service.store")
_T = TypeVar("_T")


def _translate(error: sqlite3.Error, path: Path) -> StoreError:
    """A SQLite error as the store error it means."""
    code = getattr(error, "sqlite_errorname", "") or ""
    if code == "SQLITE_FULL" or "full" in str(error):
        return StoreFull(
            f"the store at {path} is full ({error}): free disk space or raise COATED_STORE_MAX_BYTES, then retry"
        )
    if code in ("SQLITE_CORRUPT", "SQLITE_NOTADB"):
        return StoreDamaged(f"the store at {path} is damaged: {error}")
    return StoreUnavailable(f"the store at {path} is unavailable: {error}")


_WRITE_FLOOR_BYTES = 1_000_000
"""Free disk below which the store is not writable even with COATED_STORE_MIN_FREE_BYTES=0
(a save writes its record, the journal and the index pages)."""


class SQLiteStore(SQLStore):
    """
    :class:`Store` on one SQLite file in WAL mode: one connection per
    thread (WAL lets readers run while a writer commits), ``synchronous=FULL``
    so that a committed save survives a crash.

    ``max_bytes`` caps the file (SQLite's ``max_page_count``; a save past it
    is :class:`StoreFull`); ``min_free_bytes`` is the free disk space below
    which :meth:`writable` reports the store full before any work is done.
    Every SQLite error leaves as a :class:`StoreError` naming what happened.
    The schema is brought to :data:`SCHEMA_VERSION` on opening (``migrate``
    False: refused with :class:`SchemaMismatch` unless it is there).
    """

    kind = "sqlite"
    placeholder = "?"

    def __init__(
        self, path: str | Path, max_bytes: int | None = None, min_free_bytes: int = 0, migrate: bool = True
    ) -> None:
        self.path = Path(path)
        self.max_bytes = max_bytes
        self.min_free_bytes = min_free_bytes
        self._local = threading.local()
        self._connections: list[sqlite3.Connection] = []
        self._lock = threading.Lock()
        self._idle = threading.Condition(self._lock)  # notified when no call uses a connection
        self._active = 0
        self._closed = False
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise StoreUnavailable(
                f"the store directory {self.path.parent} cannot be made: {error.strerror or error}"
            ) from None

        def setup() -> tuple[int, int]:
            connection = self._connection()
            connection.execute("PRAGMA journal_mode=WAL")
            return _migrate(connection, "sqlite", apply=migrate)

        try:
            self.migrated = self._guard(setup)
        except BaseException:
            self.close()
            raise

    # -- plumbing ----------------------------------------------------------

    @contextlib.contextmanager
    def _in_use(self):
        """
        A call that uses a connection: refused once the store is closed, and
        :meth:`close` waits for it (closing a sqlite3 connection while another
        thread runs a statement on it crashes the process).
        """
        with self._lock:
            if self._closed:
                raise StoreUnavailable("the store is closed")
            self._active += 1
        try:
            yield
        finally:
            with self._lock:
                self._active -= 1
                if not self._active:
                    self._idle.notify_all()

    def _guard(self, function: Callable[[], _T]) -> _T:
        try:
            with self._in_use():
                return function()
        except sqlite3.Error as error:
            raise _translate(error, self.path) from None

    def _connection(self) -> sqlite3.Connection:
        connection = getattr(self._local, "connection", None)
        if connection is None:
            if self._closed:
                raise StoreUnavailable("the store is closed")
            connection = sqlite3.connect(self.path, timeout=30.0, check_same_thread=False)
            connection.execute("PRAGMA synchronous=FULL")
            connection.execute("PRAGMA busy_timeout=30000")
            if self.max_bytes:
                (page_size,) = connection.execute("PRAGMA page_size").fetchone()
                connection.execute(f"PRAGMA max_page_count={max(1, self.max_bytes // page_size)}")
            self._local.connection = connection
            with self._lock:
                self._connections.append(connection)
        return connection

    # -- the interface -----------------------------------------------------

    def put_fit(
        self,
        record: FitRecord,
        save: bool = True,
        expected_version: int | None = None,
        nk: dict[str, list[float]] | None = None,
    ) -> FitRecord:
        record, text, nk_json = records.prepared(record, nk)

        def write() -> FitRecord:
            connection = self._connection()
            with connection:
                # BEGIN IMMEDIATE: the write lock first, so the version read is the one written after.
                connection.execute("BEGIN IMMEDIATE")
                return queries.save(connection, "?", record, text, save, expected_version, self._decode, nk_json)

        return self._guard(write)

    def _read(self, function: Callable[[sqlite3.Connection], _T]) -> _T:
        return self._guard(lambda: function(self._connection()))

    def _write(self, function: Callable[[sqlite3.Connection], _T]) -> _T:
        """``function(connection)`` in one write transaction holding the write lock (as saves do)."""

        def write() -> _T:
            connection = self._connection()
            with connection:
                connection.execute("BEGIN IMMEDIATE")
                return function(connection)

        return self._guard(write)

    def check(self) -> None:
        try:
            with self._in_use():
                (result,) = self._connection().execute("PRAGMA quick_check").fetchone()
        except StoreError:
            raise
        except sqlite3.Error as error:
            raise StoreUnavailable(f"the store at {self.path} is unusable: {error}") from None
        if result != "ok":
            raise StoreDamaged(f"the store at {self.path} is damaged: {result}")

    def ping(self) -> None:
        """A cheap read (no integrity scan): raises :class:`StoreError` if the store cannot answer."""
        self._guard(lambda: self._connection().execute("SELECT 1 FROM saves LIMIT 1").fetchall())

    def describe(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "schema_version": SCHEMA_VERSION,
            "path": str(self.path),
            "connections": len(self._connections),
        }

    def writable(self) -> str | None:
        try:
            free = os.statvfs(self.path.parent)
            free_bytes = free.f_bavail * free.f_frsize
        except OSError as error:
            return f"the store directory {self.path.parent} cannot be read: {error}"
        if free_bytes < self.min_free_bytes:
            return (
                f"the disk of the store has {free_bytes} bytes free, less than "
                f"COATED_STORE_MIN_FREE_BYTES ({self.min_free_bytes})"
            )
        if free_bytes < _WRITE_FLOOR_BYTES:  # whatever the setting, even 0: a full disk takes no save
            return f"the disk of the store has {free_bytes} bytes free, less than one save needs ({_WRITE_FLOOR_BYTES})"
        try:
            with self._in_use():
                return self._writable_here()
        except StoreError as error:
            return str(error)
        except sqlite3.Error as error:
            return str(_translate(error, self.path))

    def _writable_here(self) -> str | None:
        """The quota and the read-only check of :meth:`writable`, on this thread's connection."""
        connection = self._connection()
        if self.max_bytes:
            (pages,) = connection.execute("PRAGMA page_count").fetchone()
            (page_size,) = connection.execute("PRAGMA page_size").fetchone()
            if (pages + 4) * page_size > self.max_bytes:
                return (
                    f"the store holds {pages * page_size} bytes, at its quota COATED_STORE_MAX_BYTES ({self.max_bytes})"
                )
        # A write statement that changes nothing: refused by a read-only
        # store; rolled back at once so that it holds no lock. It never waits
        # for another writer's lock (a probe must answer at once): a store
        # whose lock another connection holds is writable, its saves wait.
        connection.execute("PRAGMA busy_timeout=0")
        try:
            connection.execute("DELETE FROM saves WHERE 0")
        except sqlite3.OperationalError as error:
            if "locked" not in str(error):
                raise
        finally:
            connection.rollback()
            connection.execute("PRAGMA busy_timeout=30000")
        return None

    def close(self) -> None:
        """Refuse new calls, wait up to 60 s for those under way, close every connection."""
        with self._lock:
            self._closed = True
            self._idle.wait_for(lambda: not self._active, timeout=60.0)
            for connection in self._connections:
                connection.close()
            self._connections.clear()
