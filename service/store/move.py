"""
SQLite to PostgreSQL
====================

:func:`move_sqlite_to_postgres`: copy a SQLite store, every record, the
whole save log (its order and ``seq`` numbers: page cursors stay valid),
the material summaries with their versions and the drafts' n, k records, into an empty PostgreSQL store
in one transaction, and prove it with a count and a checksum computed the
same way on both sides (:func:`store_checksum`). The command is
``python -m service migrate --from-sqlite DATA_DIR/store.sqlite3`` with
``COATED_STORE_URL`` set (docs/deploy.md).
"""

from __future__ import annotations

import hashlib
import sqlite3
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .postgres import SAVE_LOCK, PostgresStore
from .records import StoreUnavailable
from .sqlite import SQLiteStore

__all__ = ["MoveReport", "store_checksum", "move_sqlite_to_postgres"]

_TABLES = {
    "fits": ("id", "kind", "material_id", "created_at", "record", "nk_id", "base_fit_id"),
    "saves": ("seq", "material_id", "fit_id", "saved_at"),
    "materials": (
        "material_id",
        "first_seq",
        "first_saved_at",
        "latest_fit_id",
        "kind",
        "name",
        "source",
        "coverage",
        "version",
        "deleted_at",
        "name_key",
    ),
    "nk_records": ("id", "created_at", "record"),
}
_ORDER = {"fits": "id", "saves": "seq", "materials": "material_id", "nk_records": "id"}
_BATCH = 1000


@dataclass(frozen=True)
class MoveReport:
    """Rows moved per table, and the checksum both stores gave."""

    fits: int
    saves: int
    materials: int
    checksum: str

    def line(self, source: str, target: str) -> str:
        return (
            f"moved {self.fits} fits, {self.saves} saves, {self.materials} materials from "
            f"{source} to {target}; checksum {self.checksum} (source and target agree)"
        )


def _rows(connection: Any, table: str):
    columns = ", ".join(_TABLES[table])
    cursor = connection.execute(f"SELECT {columns} FROM {table} ORDER BY {_ORDER[table]}")
    while batch := cursor.fetchmany(_BATCH):
        yield from batch


def store_checksum(connection: Any) -> tuple[str, dict[str, int]]:
    """
    SHA-256 of every row of the four tables in a fixed order (ids, JSON
    texts, numbers as ``repr``), and the row count of each, from an open
    sqlite3 or psycopg connection: equal for two stores holding the same.
    """
    digest = hashlib.sha256()
    counts = {}
    for table in _TABLES:
        counts[table] = 0
        digest.update(table.encode() + b"\x1d")
        for row in _rows(connection, table):
            digest.update("\x1f".join(repr(v) for v in row).encode() + b"\x1e")
            counts[table] += 1
    return "sha256:" + digest.hexdigest(), counts


def move_sqlite_to_postgres(source: str | Path, target: PostgresStore) -> MoveReport:
    """
    Copy the SQLite store at ``source`` (migrated to the current schema
    first) into ``target``, which must hold no fit; one transaction, so a
    failure leaves the target empty. Raises :class:`StoreError`.
    """
    source = Path(source)
    if not source.is_file():
        raise StoreUnavailable(f"the SQLite store {source} does not exist")
    SQLiteStore(source).close()  # brings its schema to this code's version
    with sqlite3.connect(source) as lite:
        lite.execute("BEGIN")  # one snapshot of the source, read from start to end
        want, counts = store_checksum(lite)

        def copy(connection: Any) -> str:
            connection.execute("SELECT pg_advisory_xact_lock(%s)", (SAVE_LOCK,))
            (present,) = connection.execute("SELECT COUNT(*) FROM fits").fetchone()
            if present:
                raise StoreUnavailable(
                    f"the target store {target.where} already holds {present} fits: "
                    "a SQLite store moves into an empty PostgreSQL store only"
                )
            for table, columns in _TABLES.items():
                marks = ", ".join(["%s"] * len(columns))
                sql = f"INSERT INTO {table} ({', '.join(columns)}) VALUES ({marks})"
                batch = []
                with connection.cursor() as cursor:
                    for row in _rows(lite, table):
                        batch.append(row)
                        if len(batch) == _BATCH:
                            cursor.executemany(sql, batch)
                            batch.clear()
                    if batch:
                        cursor.executemany(sql, batch)
            connection.execute(
                "SELECT setval(pg_get_serial_sequence('saves', 'seq'), "
                "GREATEST((SELECT MAX(seq) FROM saves), 1), "
                "(SELECT MAX(seq) FROM saves) IS NOT NULL)"
            )
            got, _ = store_checksum(connection)
            if got != want:
                raise StoreUnavailable(f"the copy's checksum {got} differs from the source's {want}; nothing was moved")
            return got

        checksum = target.transaction(copy)
    return MoveReport(counts["fits"], counts["saves"], counts["materials"], checksum)
