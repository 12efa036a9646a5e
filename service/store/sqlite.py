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
import threading
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable, TypeVar

from .records import (
    FIT_KINDS,
    FitRecord,
    MaterialPage,
    MaterialRow,
    RecordDamaged,
    StoreDamaged,
    StoreError,
    StoreFull,
    StoreUnavailable,
)

log = logging.getLogger("service.store")
_T = TypeVar("_T")


_SCHEMA = """
CREATE TABLE IF NOT EXISTS fits (
    id TEXT PRIMARY KEY,
    kind TEXT NOT NULL,
    material_id TEXT NOT NULL,
    created_at REAL NOT NULL,
    record TEXT NOT NULL
);
CREATE INDEX IF NOT EXISTS fits_by_material ON fits (material_id, created_at);
CREATE TABLE IF NOT EXISTS saves (
    seq INTEGER PRIMARY KEY AUTOINCREMENT,
    material_id TEXT NOT NULL,
    fit_id TEXT NOT NULL REFERENCES fits (id),
    saved_at REAL NOT NULL
);
CREATE INDEX IF NOT EXISTS saves_by_material ON saves (material_id, seq);
CREATE INDEX IF NOT EXISTS saves_by_fit ON saves (fit_id);
-- Stores written before the save log: each fit counts as saved once, in order.
INSERT INTO saves (material_id, fit_id, saved_at)
    SELECT material_id, id, created_at FROM fits
    WHERE id NOT IN (SELECT fit_id FROM saves) ORDER BY created_at, rowid;
-- One summary row per material (its first save and its latest fit), kept by
-- put_fit, so that a listing reads one short row per material it returns.
CREATE TABLE IF NOT EXISTS materials (
    material_id TEXT PRIMARY KEY,
    first_seq INTEGER NOT NULL,
    first_saved_at REAL NOT NULL,
    latest_fit_id TEXT NOT NULL,
    kind TEXT NOT NULL,
    name TEXT NOT NULL,
    source TEXT NOT NULL,
    coverage REAL
);
CREATE INDEX IF NOT EXISTS materials_by_first ON materials (kind, first_seq);
"""

_UPSERT_MATERIAL = (
    "INSERT INTO materials (material_id, first_seq, first_saved_at, latest_fit_id, kind, name, "
    "source, coverage) VALUES (?, ?, ?, ?, ?, ?, ?, ?) "
    "ON CONFLICT (material_id) DO UPDATE SET latest_fit_id = excluded.latest_fit_id, "
    "kind = excluded.kind, name = excluded.name, source = excluded.source, "
    "coverage = excluded.coverage"
)


def _translate(error: sqlite3.Error, path: Path) -> StoreError:
    """A SQLite error as the store error it means."""
    code = getattr(error, "sqlite_errorname", "") or ""
    if code == "SQLITE_FULL" or "full" in str(error):
        return StoreFull(f"the store at {path} is full ({error}): free disk space or raise "
                         "COATED_STORE_MAX_BYTES, then retry")
    if code in ("SQLITE_CORRUPT", "SQLITE_NOTADB"):
        return StoreDamaged(f"the store at {path} is damaged: {error}")
    return StoreUnavailable(f"the store at {path} is unavailable: {error}")



_WRITE_FLOOR_BYTES = 1_000_000
"""Free disk below which the store is not writable even with COATED_STORE_MIN_FREE_BYTES=0
(a save writes its record, the journal and the index pages)."""

class SQLiteStore:
    """
    :class:`Store` on one SQLite file in WAL mode: one connection per
    thread (WAL lets readers run while a writer commits), ``synchronous=FULL``
    so that a committed save survives a crash.

    ``max_bytes`` caps the file (SQLite's ``max_page_count``; a save past it
    is :class:`StoreFull`); ``min_free_bytes`` is the free disk space below
    which :meth:`writable` reports the store full before any work is done.
    Every SQLite error leaves as a :class:`StoreError` naming what happened.
    """

    def __init__(self, path: str | Path, max_bytes: int | None = None,
                 min_free_bytes: int = 0) -> None:
        self.path = Path(path)
        self.max_bytes = max_bytes
        self.min_free_bytes = min_free_bytes
        self._local = threading.local()
        self._connections: list[sqlite3.Connection] = []
        self._lock = threading.Lock()
        self._closed = False
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise StoreUnavailable(f"the store directory {self.path.parent} cannot be made: "
                                   f"{error.strerror or error}") from None

        def setup() -> None:
            connection = self._connection()
            connection.execute("PRAGMA journal_mode=WAL")
            with connection:
                connection.executescript(_SCHEMA)
            self._backfill_materials(connection)

        self._guard(setup)

    # -- plumbing ----------------------------------------------------------

    def _guard(self, function: Callable[[], _T]) -> _T:
        try:
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

    def _decode(self, fit_id: str, text: Any) -> FitRecord:
        try:
            return FitRecord.from_json(text)
        except (TypeError, ValueError) as error:
            log.error("stored fit %s cannot be decoded: %s", fit_id, error)
            raise RecordDamaged(f"the stored record of fit {fit_id} is damaged and cannot be "
                                "read; the rest of the store is unaffected") from None

    def _backfill_materials(self, connection: sqlite3.Connection) -> None:
        """Summary rows for materials saved before the summary table existed."""
        missing = connection.execute(
            "SELECT s.material_id, MIN(s.seq), MIN(s.saved_at), MAX(s.seq) FROM saves s "
            "WHERE s.material_id NOT IN (SELECT material_id FROM materials) GROUP BY s.material_id"
        ).fetchall()
        for material_id, first_seq, first_at, last_seq in missing:
            for (fit_id, text) in connection.execute(
                "SELECT f.id, f.record FROM saves s JOIN fits f ON f.id = s.fit_id "
                "WHERE s.material_id = ? AND s.seq <= ? ORDER BY s.seq DESC", (material_id, last_seq)
            ).fetchall():
                try:
                    record = FitRecord.from_json(text)
                except (TypeError, ValueError) as error:
                    log.error("stored fit %s cannot be decoded, skipped: %s", fit_id, error)
                    continue
                with connection:
                    connection.execute(_UPSERT_MATERIAL, (
                        material_id, first_seq, first_at, record.id, record.kind, record.name,
                        record.source, record.coverage))
                break

    # -- the interface -----------------------------------------------------

    def put_fit(self, record: FitRecord, save: bool = True) -> FitRecord:
        if not record.created_at:
            record = FitRecord(**{**asdict(record), "created_at": time.time()})
        text = record.to_json()

        def write() -> FitRecord:
            connection = self._connection()
            with connection:
                connection.execute(
                    "INSERT OR IGNORE INTO fits (id, kind, material_id, created_at, record) "
                    "VALUES (?, ?, ?, ?, ?)",
                    (record.id, record.kind, record.material_id, record.created_at, text),
                )
                stored_text = connection.execute(
                    "SELECT record FROM fits WHERE id = ?", (record.id,)).fetchone()[0]
                stored = self._decode(record.id, stored_text)
                if not save:  # a draft: stored, reachable by id, listed under no material
                    return stored
                now = time.time()
                seq = connection.execute(
                    "INSERT INTO saves (material_id, fit_id, saved_at) VALUES (?, ?, ?)",
                    (stored.material_id, stored.id, now),
                ).lastrowid
                connection.execute(_UPSERT_MATERIAL, (
                    stored.material_id, seq, now, stored.id, stored.kind, stored.name,
                    stored.source, stored.coverage))
            return stored

        return self._guard(write)

    def expire_drafts(self, older_than: float, max_bytes: int) -> int:
        def sweep() -> int:
            connection = self._connection()
            with connection:
                rows = connection.execute(
                    "SELECT id, created_at, length(record) FROM fits WHERE NOT EXISTS "
                    "(SELECT 1 FROM saves WHERE saves.fit_id = fits.id) ORDER BY created_at DESC").fetchall()
                kept, doomed = 0, []
                for fit_id, created_at, size in rows:  # newest first: the oldest go past the quota
                    if created_at < older_than or kept + size > max_bytes:
                        doomed.append((fit_id, fit_id))
                    else:
                        kept += size
                # A draft saved meanwhile (by another connection) stays.
                connection.executemany(
                    "DELETE FROM fits WHERE id = ? AND NOT EXISTS (SELECT 1 FROM saves WHERE fit_id = ?)", doomed)
            return len(doomed)

        return self._guard(sweep)

    def get_fit(self, fit_id: str) -> FitRecord | None:
        row = self._guard(lambda: self._connection().execute(
            "SELECT record FROM fits WHERE id = ?", (fit_id,)).fetchone())
        return None if row is None else self._decode(fit_id, row[0])

    def latest_fit(self, material_id: str) -> FitRecord | None:
        """The latest decodable fit of a material (a damaged one is logged and passed over)."""
        rows = self._guard(lambda: self._connection().execute(
            "SELECT f.id, f.record FROM saves s JOIN fits f ON f.id = s.fit_id "
            "WHERE s.material_id = ? ORDER BY s.seq DESC LIMIT 16", (material_id,)).fetchall())
        for fit_id, text in rows:
            try:
                return self._decode(fit_id, text)
            except RecordDamaged:
                continue
        return None

    def latest_fit_ids(self, material_ids: list[str]) -> dict[str, str]:
        if not material_ids:
            return {}
        marks = ",".join("?" * len(material_ids))
        rows = self._guard(lambda: self._connection().execute(
            f"SELECT material_id, latest_fit_id FROM materials WHERE material_id IN ({marks})",
            list(material_ids)).fetchall())
        return dict(rows)

    def material_page(self, after: int | None, limit: int) -> MaterialPage:
        rows = self._guard(lambda: self._connection().execute(
            "SELECT material_id, name, source, coverage, kind, latest_fit_id, first_saved_at, "
            "first_seq FROM materials WHERE kind != 'library' AND first_seq > ? "
            "ORDER BY first_seq LIMIT ?", (after or 0, limit + 1)).fetchall())
        out, skipped = [], []
        for material_id, name, source, coverage, kind, latest, first_at, seq in rows[:limit]:
            if (kind not in FIT_KINDS or not isinstance(name, str) or not isinstance(source, str)
                    or not (coverage is None or isinstance(coverage, float))):
                log.error("the summary of material %r cannot be read, skipped", material_id)
                skipped.append(str(material_id))
                continue
            out.append(MaterialRow(material_id=material_id, name=name, source=source,
                                   coverage=coverage, kind=kind, latest_fit_id=latest,
                                   created_at=first_at, seq=seq))
        next_cursor = rows[limit - 1][7] if len(rows) > limit else None
        return MaterialPage(out, next_cursor, skipped)

    def saved_materials(self) -> list[MaterialRow]:
        rows: list[MaterialRow] = []
        cursor = None
        while True:
            page = self.material_page(cursor, 1000)
            rows.extend(page.rows)
            if page.next_cursor is None:
                return rows
            cursor = page.next_cursor

    def check(self) -> None:
        try:
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

    def writable(self) -> str | None:
        try:
            free = os.statvfs(self.path.parent)
            free_bytes = free.f_bavail * free.f_frsize
        except OSError as error:
            return f"the store directory {self.path.parent} cannot be read: {error}"
        if free_bytes < self.min_free_bytes:
            return (f"the disk of the store has {free_bytes} bytes free, less than "
                    f"COATED_STORE_MIN_FREE_BYTES ({self.min_free_bytes})")
        if free_bytes < _WRITE_FLOOR_BYTES:  # whatever the setting, even 0: a full disk takes no save
            return (f"the disk of the store has {free_bytes} bytes free, less than one save needs "
                    f"({_WRITE_FLOOR_BYTES})")
        try:
            connection = self._connection()
            if self.max_bytes:
                (pages,) = connection.execute("PRAGMA page_count").fetchone()
                (page_size,) = connection.execute("PRAGMA page_size").fetchone()
                if (pages + 4) * page_size > self.max_bytes:
                    return (f"the store holds {pages * page_size} bytes, at its quota "
                            f"COATED_STORE_MAX_BYTES ({self.max_bytes})")
            # A write statement that changes nothing: refused by a read-only
            # store; rolled back at once so that it holds no lock.
            try:
                connection.execute("DELETE FROM saves WHERE 0")
            finally:
                connection.rollback()
        except StoreError as error:
            return str(error)
        except sqlite3.Error as error:
            return str(_translate(error, self.path))
        return None

    def close(self) -> None:
        with self._lock:
            self._closed = True
            for connection in self._connections:
                connection.close()
            self._connections.clear()
