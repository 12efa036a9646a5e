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

from __future__ import annotations

import json
import sqlite3
import threading
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

__all__ = ["FIT_KINDS", "FitRecord", "MaterialRow", "Store", "SQLiteStore"]

FIT_KINDS = ("library", "nk", "curves")
"""How a fit was made: a built-in material, measured n, k, edited curves."""


@dataclass(frozen=True)
class FitRecord:
    """
    One stored fit.

    Attributes
    ----------
    id
        Content address of the inputs, 32 lowercase hex digits.
    kind
        One of :data:`FIT_KINDS`.
    material_id
        The material the fit belongs to: the library name for library fits,
        a content address of the n, k for uploads, any id for curve fits.
    name, source
        Display name and citation of the data.
    material
        The pack JSON view of the fitted material
        (:func:`fitting.pack.material_to_json`, float16 coefficients).
    metrics, timings, convergence
        Metrics against the reference, seconds per stage, solver report.
    objective
        The fitted objective.
    coverage
        Covered fraction of 360-830 nm (None for fits without n, k).
    library_material
        Name of the built-in material (library fits).
    nk
        ``{"wavelength_nm", "n", "k"}`` as lists (fits of measured data).
    base_fit_id
        The fit a curve fit started from, if any.
    provenance
        Free-form JSON about how the fit was made.
    created_at
        Unix time of the first save.
    """

    id: str
    kind: str
    material_id: str
    name: str
    source: str
    material: dict[str, Any]
    metrics: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    convergence: dict[str, Any] = field(default_factory=dict)
    objective: str = ""
    coverage: float | None = None
    library_material: str | None = None
    nk: dict[str, list[float]] | None = None
    base_fit_id: str | None = None
    provenance: dict[str, Any] = field(default_factory=dict)
    created_at: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in FIT_KINDS:
            raise ValueError(f"`kind` must be one of {', '.join(FIT_KINDS)}, got {self.kind!r}")

    def to_json(self) -> str:
        return json.dumps(asdict(self), allow_nan=False, separators=(",", ":"))

    @classmethod
    def from_json(cls, text: str) -> "FitRecord":
        return cls(**json.loads(text))


@dataclass(frozen=True)
class MaterialRow:
    """A saved (non-library) material: its latest fit's name, source and coverage."""

    material_id: str
    name: str
    source: str
    coverage: float | None
    kind: str
    latest_fit_id: str
    created_at: float


@runtime_checkable
class Store(Protocol):
    """The store interface of the service (thread-safe implementations)."""

    def put_fit(self, record: FitRecord, save: bool = True) -> FitRecord:
        """
        Save ``record`` unless its id exists, and log the save (the fit
        becomes its material's latest); return the stored record. With
        ``save`` False (a draft) the record is stored but not logged: it is
        reachable by id and lists under no material until saved.
        """

    def get_fit(self, fit_id: str) -> FitRecord | None:
        """The record of ``fit_id``, or None."""

    def latest_fit(self, material_id: str) -> FitRecord | None:
        """The fit of a material saved last, or None."""

    def saved_materials(self) -> list[MaterialRow]:
        """Materials with at least one non-library fit, oldest first."""

    def check(self) -> None:
        """Raise ``RuntimeError`` if the store is unusable or damaged."""

    def close(self) -> None:
        """Release connections."""


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
-- Stores written before the save log: each fit counts as saved once, in order.
INSERT INTO saves (material_id, fit_id, saved_at)
    SELECT material_id, id, created_at FROM fits
    WHERE id NOT IN (SELECT fit_id FROM saves) ORDER BY created_at, rowid;
"""


class SQLiteStore:
    """
    :class:`Store` on one SQLite file in WAL mode: one connection per
    thread (WAL lets readers run while a writer commits), ``synchronous=FULL``
    so that a committed save survives a crash.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._local = threading.local()
        self._connections: list[sqlite3.Connection] = []
        self._lock = threading.Lock()
        self._closed = False
        connection = self._connection()
        connection.execute("PRAGMA journal_mode=WAL")
        with connection:
            connection.executescript(_SCHEMA)

    def _connection(self) -> sqlite3.Connection:
        connection = getattr(self._local, "connection", None)
        if connection is None:
            if self._closed:
                raise RuntimeError("the store is closed")
            connection = sqlite3.connect(self.path, timeout=30.0, check_same_thread=False)
            connection.execute("PRAGMA synchronous=FULL")
            connection.execute("PRAGMA busy_timeout=30000")
            self._local.connection = connection
            with self._lock:
                self._connections.append(connection)
        return connection

    def put_fit(self, record: FitRecord, save: bool = True) -> FitRecord:
        if not record.created_at:
            record = FitRecord(**{**asdict(record), "created_at": time.time()})
        connection = self._connection()
        with connection:
            connection.execute(
                "INSERT OR IGNORE INTO fits (id, kind, material_id, created_at, record) "
                "VALUES (?, ?, ?, ?, ?)",
                (record.id, record.kind, record.material_id, record.created_at, record.to_json()),
            )
            if save:
                connection.execute(
                    "INSERT INTO saves (material_id, fit_id, saved_at) "
                    "SELECT material_id, id, ? FROM fits WHERE id = ?",
                    (time.time(), record.id),
                )
        stored = self.get_fit(record.id)
        assert stored is not None
        return stored

    def get_fit(self, fit_id: str) -> FitRecord | None:
        row = self._connection().execute(
            "SELECT record FROM fits WHERE id = ?", (fit_id,)
        ).fetchone()
        return None if row is None else FitRecord.from_json(row[0])

    def latest_fit(self, material_id: str) -> FitRecord | None:
        row = self._connection().execute(
            "SELECT f.record FROM saves s JOIN fits f ON f.id = s.fit_id "
            "WHERE s.material_id = ? ORDER BY s.seq DESC LIMIT 1",
            (material_id,),
        ).fetchone()
        return None if row is None else FitRecord.from_json(row[0])

    def saved_materials(self) -> list[MaterialRow]:
        rows = self._connection().execute(
            "SELECT f.record, m.first FROM ("
            "  SELECT s.material_id, MIN(s.saved_at) AS first, MAX(s.seq) AS last "
            "  FROM saves s JOIN fits f ON f.id = s.fit_id WHERE f.kind != 'library' "
            "  GROUP BY s.material_id"
            ") m JOIN saves s ON s.seq = m.last JOIN fits f ON f.id = s.fit_id "
            "ORDER BY m.first, m.material_id"
        ).fetchall()
        out = []
        for text, first in rows:
            record = FitRecord.from_json(text)
            out.append(
                MaterialRow(
                    material_id=record.material_id, name=record.name, source=record.source,
                    coverage=record.coverage, kind=record.kind, latest_fit_id=record.id,
                    created_at=first,
                )
            )
        return out

    def check(self) -> None:
        try:
            (result,) = self._connection().execute("PRAGMA quick_check").fetchone()
        except sqlite3.Error as error:
            raise RuntimeError(f"the store at {self.path} is unusable: {error}") from None
        if result != "ok":
            raise RuntimeError(f"the store at {self.path} is damaged: {result}")

    def close(self) -> None:
        with self._lock:
            self._closed = True
            for connection in self._connections:
                connection.close()
            self._connections.clear()
