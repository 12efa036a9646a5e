"""
Fit store
=========

Where fits are kept: one small interface, :class:`Store`, and its embedded
implementation on SQLite in WAL mode, :class:`SQLiteStore`.

-   :class:`FitRecord`: one stored fit, with or without measured n, k (fits
    from edited curves have none).
-   :class:`MaterialRow`: a saved material as listed by ``GET /materials``.
-   :class:`Store`: the interface the routes use.
-   :class:`SQLiteStore`: the embedded store.

Records are content addressed (the id is a hash of the fit's inputs) and
written once: ``put_fit`` of an existing id keeps the first record, nothing
is ever updated or deleted, so a save that was answered is never lost.
Every ``put_fit`` also appends to an append-only log of saves, so that the
latest fit of a material is the one saved last, even when it is an earlier
fit saved again (an artist's undo, then save). Each save is one transaction
committed with ``synchronous=FULL`` before the request is answered, so it
survives a crash of the process (and of the machine) once answered.

Replacing SQLite by a server database (several service instances sharing one
store) means a second class with the same methods, e.g. on PostgreSQL
with ``INSERT ... ON CONFLICT (id) DO NOTHING`` for the record and a
``BIGSERIAL`` save log in ``put_fit``, and a JSONB column for the record;
see ``docs/service.md``.
"""

from .records import (
    FIT_KINDS,
    FitRecord,
    MaterialPage,
    MaterialRow,
    RecordDamaged,
    Store,
    StoreDamaged,
    StoreError,
    StoreFull,
    StoreUnavailable,
)
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
]
