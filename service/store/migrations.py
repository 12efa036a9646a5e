"""
Schema migrations
=================

One versioned schema for both stores: the same tables, the same version
numbers, one list of steps per dialect. A store records what it has
applied in ``schema_migrations(version, description, applied_at)``; a store
written before that table existed is version 0.

-   :data:`SCHEMA_VERSION`: the version this code knows.
-   :func:`migrate`: bring a store to :data:`SCHEMA_VERSION` (or only read
    its version), inside one transaction that holds the store's write lock
    (SQLite ``BEGIN IMMEDIATE``, PostgreSQL an advisory lock), so replicas
    starting at once apply each step once.

A store whose schema is newer than :data:`SCHEMA_VERSION` is refused
(:class:`service.store.SchemaMismatch`): the code would not know its
columns. Versions:

1.  ``fits``, the save log ``saves``, the summary ``materials`` (the schema
    of the SQLite store before versions; its two back-fills for older files).
2.  ``materials.version``: the number of saves of the material, the
    version a save may expect (``put_fit(..., expected_version=)``; 409
    when another save came first).
3.  the index ``saves_by_fit``: the drafts' sweep finds the records no
    save refers to (``expire_drafts``).
4.  ``materials.deleted_at``: a material in the bin (a soft delete; NULL:
    not deleted), and the index ``materials_by_name`` (a save or a rename
    finds the material called a name).
5.  ``nk_records(id, created_at, record)``: an n, k kept once,
    content-addressed, for the drafts on an inline n, k (``put_fit(...,
    nk=)``), and ``fits.nk_id`` with the index ``fits_by_nk``: the fit that
    refers to one (the drafts' sweep removes those no fit refers to).
6.  ``materials.name_key``: the name's look-alike key
    (:func:`service.store.names.name_key`, filled in for the rows there
    are), and the index ``materials_by_name_key``: a save or a rename
    finds a material whose name looks the same.
7.  ``fits.base_fit_id`` (filled in from the records there are) and the
    index ``fits_by_base``: the drafts' sweep keeps every draft a saved
    fit starts from, and the drafts those start from; ``fits.kept_until``:
    a draft a link was made to is kept until then (``keep_draft``).
"""

from __future__ import annotations

import json
import logging
import time
from typing import Any, Callable, Union

from .names import name_key
from .records import FitRecord, SchemaMismatch

__all__ = ["SCHEMA_VERSION", "MIGRATIONS", "migrate", "UPSERT_MATERIAL"]

log = logging.getLogger("service.store")

Step = Union[str, Callable[[Any, str], None]]
"""One SQL statement, or a function of (connection, dialect)."""

UPSERT_MATERIAL = (
    "INSERT INTO materials (material_id, first_seq, first_saved_at, latest_fit_id, kind, name, "
    "source, coverage, version, name_key) VALUES ({p}, {p}, {p}, {p}, {p}, {p}, {p}, {p}, 1, {p}) "
    "ON CONFLICT (material_id) DO UPDATE SET latest_fit_id = excluded.latest_fit_id, "
    "kind = excluded.kind, name = excluded.name, name_key = excluded.name_key, source = excluded.source, "
    "coverage = excluded.coverage, version = materials.version + 1, deleted_at = NULL"
)
"""A save's summary row (``{p}``: the dialect's placeholder); a new material is version 1,
a save of a material in the bin takes it out."""


def _backfill_materials(connection: Any, dialect: str) -> None:
    """Summary rows for materials saved before the summary table existed (SQLite stores)."""
    missing = connection.execute(
        "SELECT s.material_id, MIN(s.seq), MIN(s.saved_at), MAX(s.seq) FROM saves s "
        "WHERE s.material_id NOT IN (SELECT material_id FROM materials) GROUP BY s.material_id"
    ).fetchall()
    for material_id, first_seq, first_at, last_seq in missing:
        for fit_id, text in connection.execute(
            "SELECT f.id, f.record FROM saves s JOIN fits f ON f.id = s.fit_id "
            "WHERE s.material_id = ? AND s.seq <= ? ORDER BY s.seq DESC",
            (material_id, last_seq),
        ).fetchall():
            try:
                record = FitRecord.from_json(text)
            except (TypeError, ValueError) as error:
                log.error("stored fit %s cannot be decoded, skipped: %s", fit_id, error)
                continue
            connection.execute(
                "INSERT INTO materials (material_id, first_seq, first_saved_at, latest_fit_id, kind, "
                "name, source, coverage) VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (material_id, first_seq, first_at, record.id, record.kind, record.name, record.source, record.coverage),
            )
            break


_SQLITE_V1: list[Step] = [
    "CREATE TABLE IF NOT EXISTS fits (id TEXT PRIMARY KEY, kind TEXT NOT NULL, "
    "material_id TEXT NOT NULL, created_at REAL NOT NULL, record TEXT NOT NULL)",
    "CREATE INDEX IF NOT EXISTS fits_by_material ON fits (material_id, created_at)",
    "CREATE TABLE IF NOT EXISTS saves (seq INTEGER PRIMARY KEY AUTOINCREMENT, "
    "material_id TEXT NOT NULL, fit_id TEXT NOT NULL REFERENCES fits (id), saved_at REAL NOT NULL)",
    "CREATE INDEX IF NOT EXISTS saves_by_material ON saves (material_id, seq)",
    # Stores written before the save log: each fit counts as saved once, in order.
    "INSERT INTO saves (material_id, fit_id, saved_at) SELECT material_id, id, created_at FROM fits "
    "WHERE id NOT IN (SELECT fit_id FROM saves) ORDER BY created_at, rowid",
    "CREATE TABLE IF NOT EXISTS materials (material_id TEXT PRIMARY KEY, first_seq INTEGER NOT NULL, "
    "first_saved_at REAL NOT NULL, latest_fit_id TEXT NOT NULL, kind TEXT NOT NULL, "
    "name TEXT NOT NULL, source TEXT NOT NULL, coverage REAL)",
    "CREATE INDEX IF NOT EXISTS materials_by_first ON materials (kind, first_seq)",
    _backfill_materials,
]

_POSTGRES_V1: list[Step] = [
    "CREATE TABLE fits (id TEXT PRIMARY KEY, kind TEXT NOT NULL, material_id TEXT NOT NULL, "
    "created_at DOUBLE PRECISION NOT NULL, record TEXT NOT NULL)",
    "CREATE INDEX fits_by_material ON fits (material_id, created_at)",
    "CREATE TABLE saves (seq BIGINT GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY, "
    "material_id TEXT NOT NULL, fit_id TEXT NOT NULL REFERENCES fits (id), "
    "saved_at DOUBLE PRECISION NOT NULL)",
    "CREATE INDEX saves_by_material ON saves (material_id, seq)",
    "CREATE TABLE materials (material_id TEXT PRIMARY KEY, first_seq BIGINT NOT NULL, "
    "first_saved_at DOUBLE PRECISION NOT NULL, latest_fit_id TEXT NOT NULL, kind TEXT NOT NULL, "
    "name TEXT NOT NULL, source TEXT NOT NULL, coverage DOUBLE PRECISION)",
    "CREATE INDEX materials_by_first ON materials (kind, first_seq)",
]

_V2: list[Step] = [
    "ALTER TABLE materials ADD COLUMN version BIGINT NOT NULL DEFAULT 0",
    "UPDATE materials SET version = (SELECT COUNT(*) FROM saves s WHERE s.material_id = materials.material_id)",
]

_V3: list[Step] = [
    "CREATE INDEX IF NOT EXISTS saves_by_fit ON saves (fit_id)",
]

_V4: list[Step] = [
    "ALTER TABLE materials ADD COLUMN deleted_at DOUBLE PRECISION",
    "CREATE INDEX IF NOT EXISTS materials_by_name ON materials (kind, name)",
]

_V5: list[Step] = [
    "CREATE TABLE IF NOT EXISTS nk_records (id TEXT PRIMARY KEY, created_at DOUBLE PRECISION NOT NULL, "
    "record TEXT NOT NULL)",
    "ALTER TABLE fits ADD COLUMN nk_id TEXT",
    "CREATE INDEX IF NOT EXISTS fits_by_nk ON fits (nk_id)",
]


def _fill_name_keys(connection: Any, dialect: str) -> None:
    """Each material's :func:`name_key` (computed here: SQL has no TR39 skeleton)."""
    p = "?" if dialect == "sqlite" else "%s"
    for material_id, name in connection.execute("SELECT material_id, name FROM materials").fetchall():
        connection.execute(
            f"UPDATE materials SET name_key = {p} WHERE material_id = {p}", (name_key(name), material_id)
        )


_V6: list[Step] = [
    "ALTER TABLE materials ADD COLUMN name_key TEXT",
    _fill_name_keys,
    "CREATE INDEX IF NOT EXISTS materials_by_name_key ON materials (kind, name_key)",
]


def _fill_base_fit_ids(connection: Any, dialect: str) -> None:
    """Each curve fit's ``base_fit_id``, read from its record (the column is new)."""
    p = "?" if dialect == "sqlite" else "%s"
    for fit_id, text in connection.execute("SELECT id, record FROM fits WHERE kind = 'curves'").fetchall():
        try:
            base = json.loads(text).get("base_fit_id")
        except (TypeError, ValueError, AttributeError) as error:
            log.error("stored fit %s cannot be decoded, its base is not known: %s", fit_id, error)
            continue
        if isinstance(base, str):
            connection.execute(f"UPDATE fits SET base_fit_id = {p} WHERE id = {p}", (base, fit_id))


_V7: list[Step] = [
    "ALTER TABLE fits ADD COLUMN base_fit_id TEXT",
    _fill_base_fit_ids,
    "CREATE INDEX IF NOT EXISTS fits_by_base ON fits (base_fit_id)",
    "ALTER TABLE fits ADD COLUMN kept_until DOUBLE PRECISION",
]

MIGRATIONS: dict[str, list[tuple[int, str, list[Step]]]] = {
    "sqlite": [
        (1, "fits, save log, material summaries", _SQLITE_V1),
        (2, "material versions", _V2),
        (3, "saves by fit (the drafts' sweep)", _V3),
        (4, "materials in the bin, by name", _V4),
        (5, "n, k records of drafts", _V5),
        (6, "look-alike keys of names", _V6),
        (7, "the base each fit starts from, drafts kept for links", _V7),
    ],
    "postgresql": [
        (1, "fits, save log, material summaries", _POSTGRES_V1),
        (2, "material versions", _V2),
        (3, "saves by fit (the drafts' sweep)", _V3),
        (4, "materials in the bin, by name", _V4),
        (5, "n, k records of drafts", _V5),
        (6, "look-alike keys of names", _V6),
        (7, "the base each fit starts from, drafts kept for links", _V7),
    ],
}
SCHEMA_VERSION = max(version for version, _, _ in MIGRATIONS["sqlite"])
"""The schema version this code reads and writes."""

_PG_LOCK_KEY = 0x636F61746564  # "coated": the advisory lock of migrations
_TABLE = (
    "CREATE TABLE IF NOT EXISTS schema_migrations (version INTEGER PRIMARY KEY, "
    "description TEXT NOT NULL, applied_at DOUBLE PRECISION NOT NULL)"
)


def _current(connection: Any) -> int:
    (version,) = connection.execute("SELECT COALESCE(MAX(version), 0) FROM schema_migrations").fetchone()
    return int(version)


def migrate(connection: Any, dialect: str, apply: bool = True) -> tuple[int, int]:
    """
    Bring the store on ``connection`` (sqlite3 or psycopg, no transaction
    open) to :data:`SCHEMA_VERSION`; return ``(before, after)``.

    With ``apply`` False nothing is changed, and an older schema is refused
    too (``python -m service migrate`` applies it). Raises
    :class:`SchemaMismatch` for a schema newer than this code, or older
    with ``apply`` False.
    """
    placeholder = "?" if dialect == "sqlite" else "%s"
    if dialect == "sqlite":
        connection.execute("BEGIN IMMEDIATE")
    else:
        connection.execute("SELECT pg_advisory_xact_lock(%s)", (_PG_LOCK_KEY,))
    try:
        connection.execute(_TABLE)
        before = _current(connection)
        if before > SCHEMA_VERSION:
            raise SchemaMismatch(
                f"the store's schema is version {before}, newer than this code knows "
                f"({SCHEMA_VERSION}): run the newer service, or restore a backup of the store"
            )
        if before < SCHEMA_VERSION and not apply:
            raise SchemaMismatch(
                f"the store's schema is version {before}, this code needs {SCHEMA_VERSION}: "
                "run `python -m service migrate` (or start with COATED_STORE_MIGRATE=true)"
            )
        for version, description, steps in MIGRATIONS[dialect]:
            if version <= before:
                continue
            for step in steps:
                if callable(step):
                    step(connection, dialect)
                else:
                    connection.execute(step)
            connection.execute(
                f"INSERT INTO schema_migrations (version, description, applied_at) "
                f"VALUES ({placeholder}, {placeholder}, {placeholder})",
                (version, description, time.time()),
            )
            log.warning("store schema: applied version %d (%s)", version, description)
        connection.commit()
    except BaseException:
        connection.rollback()
        raise
    return before, max(before, SCHEMA_VERSION)
