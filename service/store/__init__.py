"""
Fit store
=========

Where fits are kept: one small interface, :class:`Store`, its embedded
implementation on SQLite in WAL mode, :class:`SQLiteStore`, and the shared
one on PostgreSQL for any number of service replicas, :class:`PostgresStore`
(``service.store.postgres``, imported on use: psycopg loads only then).

-   :class:`FitRecord`: one stored fit, with or without measured n, k (fits
    from edited curves have none).
-   :class:`MaterialRow`: a saved material as listed by ``GET /materials``.
-   :class:`Store`: the interface the routes use.
-   :class:`SQLiteStore`: the embedded store.
-   :func:`open_store`: the store the settings name (``COATED_STORE_URL``).
-   :data:`SCHEMA_VERSION`, :func:`migrate`: the versioned schema of both
    (``service.store.migrations``); :mod:`service.store.queries` the SQL
    both run; :mod:`service.store.move` SQLite to PostgreSQL.

Records are content addressed (the id is a hash of the fit's inputs) and
written once: ``put_fit`` of an existing id keeps the first record, no
record or save is ever updated or deleted, so a save that was answered is
never lost. What an artist changes is the material's summary row: its name
(``rename_material``) and whether it is in the bin (``delete_material``, a
soft delete; ``restore_material``); only drafts, never saved, are removed
(``expire_drafts``).
Every ``put_fit`` also appends to an append-only log of saves, so that the
latest fit of a material is the one saved last, even when it is an earlier
fit saved again (an artist's undo, then save). Each save is one transaction
committed with ``synchronous=FULL`` before the request is answered, so it
survives a crash of the process (and of the machine) once answered.

Saves are serialised (SQLite's write lock; an advisory lock on
PostgreSQL), so the save log's order is the commit order on both, and a
save that names the version it expects (``expected_version``) is refused
with :class:`StoreConflict` (409) when another save came first.
"""

from .records import (
    FIT_KINDS,
    FitRecord,
    MaterialPage,
    MaterialRow,
    NameTaken,
    RecordDamaged,
    SchemaMismatch,
    Store,
    StoreConflict,
    StoreDamaged,
    StoreError,
    StoreFull,
    StoreUnavailable,
    VersionRow,
)
from .migrations import SCHEMA_VERSION, migrate
from .opening import open_store
from .sqlite import SQLiteStore

__all__ = [
    "FIT_KINDS",
    "FitRecord",
    "MaterialRow",
    "MaterialPage",
    "Store",
    "SQLiteStore",
    "StoreError",
    "StoreFull",
    "StoreUnavailable",
    "StoreDamaged",
    "RecordDamaged",
    "StoreConflict",
    "NameTaken",
    "VersionRow",
    "SchemaMismatch",
    "SCHEMA_VERSION",
    "migrate",
    "open_store",
]
