"""
Records, rows, errors and the store interface
=============================================

:class:`FitRecord` (one stored fit), :class:`MaterialRow` and
:class:`MaterialPage` (the listing), the :class:`StoreError` family (what a
failed store call means, with its HTTP status) and :class:`Store`, the
interface every store implements (:mod:`service.store.sqlite`,
:mod:`service.store.postgres`).
"""

from __future__ import annotations

import json
import sqlite3
import time
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Callable, Protocol, runtime_checkable

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
        (:func:`fitting.models.pack.material_to_json`, float16 coefficients).
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
    nk_id
        The n, k record holding this fit's n, k (:meth:`Store.put_fit`'s
        ``nk``, :meth:`Store.get_nk`) instead of ``nk``: a draft on an
        inline n, k keeps it once, content-addressed, not a copy per draft.
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
    nk_id: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in FIT_KINDS:
            raise ValueError(f"`kind` must be one of {', '.join(FIT_KINDS)}, got {self.kind!r}")

    def to_json(self) -> str:
        return json.dumps(asdict(self), allow_nan=False, separators=(",", ":"))

    @classmethod
    def from_json(cls, text: str) -> "FitRecord":
        return cls(**json.loads(text))


def prepared(record: FitRecord, nk: dict[str, list[float]] | None) -> tuple[FitRecord, str, Callable[[], str] | None]:
    """
    What a store's ``put_fit`` writes: the record (its ``created_at`` set
    when it has none), its JSON, and what makes the JSON of the n, k record
    ``nk`` (None without one; ``nk`` needs the record's ``nk_id``), called
    only when the store does not hold that record yet: n, k records are
    content-addressed, and a live step on a 20,000-sample inline base
    would otherwise write 0.6 MB of JSON each step to be dropped.
    """
    if nk is not None and record.nk_id is None:
        raise TypeError(f"fit {record.id}: an n, k record needs the fit's `nk_id`")
    if not record.created_at:
        record = replace(record, created_at=time.time())
    nk_json = (
        None
        if nk is None
        else lambda: json.dumps(
            {key: nk[key] for key in ("wavelength_nm", "n", "k")}, allow_nan=False, separators=(",", ":")
        )
    )
    return record, record.to_json(), nk_json


def nk_from_json(nk_id: str, text: str) -> dict[str, list[float]]:
    """An n, k record's ``{"wavelength_nm", "n", "k"}`` (:class:`RecordDamaged` when it cannot be read)."""
    try:
        nk = json.loads(text)
        return {key: list(nk[key]) for key in ("wavelength_nm", "n", "k")}
    except (TypeError, ValueError, KeyError) as error:
        raise RecordDamaged(
            f"the stored n, k record {nk_id} is damaged and cannot be read ({error}); "
            "the rest of the store is unaffected"
        ) from None


@dataclass(frozen=True)
class MaterialRow:
    """A material's summary row: its latest fit's name, source, coverage and id."""

    material_id: str
    name: str
    source: str
    coverage: float | None
    kind: str
    latest_fit_id: str
    created_at: float
    seq: int = 0
    version: int = 0
    deleted_at: float | None = None


@dataclass(frozen=True)
class VersionRow:
    """
    One save of a material: its ``version`` (1 for the first save), the
    fit saved, when, and the record (None when it cannot be decoded).
    """

    version: int
    fit_id: str
    saved_at: float
    record: "FitRecord | None"


@dataclass(frozen=True)
class MaterialPage:
    """
    One page of saved materials, oldest first; ``next_cursor`` continues
    after the last row (None at the end); ``skipped`` names rows that could
    not be read (reported, not fatal to the rest).
    """

    rows: list[MaterialRow]
    next_cursor: int | None
    skipped: list[str] = field(default_factory=list)


class StoreError(RuntimeError):
    """
    The store cannot do what was asked; ``status`` is the HTTP answer,
    ``retry_after`` the seconds a client should wait (503 and 507).
    """

    status = 503
    retry_after = 30

    def __init__(self, message: str, retry_after: int | None = None) -> None:
        super().__init__(message)
        if retry_after is not None:
            self.retry_after = retry_after


class StoreFull(StoreError):
    """No room for the save: the disk (or the store's quota) is full (507)."""

    status = 507


class StoreUnavailable(StoreError):
    """The store cannot be read or written (read-only, missing, I/O error) (503)."""

    status = 503


class StoreDamaged(StoreUnavailable, sqlite3.DatabaseError):
    """The store's file is not a sound SQLite database (503; at start-up: exit)."""


class SchemaMismatch(StoreUnavailable):
    """The store's schema is not the one this code knows (503; at start-up: exit)."""


class StoreConflict(StoreError):
    """
    A save that expected another version of its material: another save
    came first (409). ``version`` and ``latest_fit_id`` are the material's now.
    """

    status = 409
    field = "expected_version"
    """The request field the conflict is about (``errors[0].loc``)."""
    type = "version_conflict"

    def __init__(self, message: str, version: int = 0, latest_fit_id: str | None = None) -> None:
        super().__init__(message)
        self.version, self.latest_fit_id = version, latest_fit_id


class NameTaken(StoreConflict):
    """A rename (or a save) to the name of another saved material of the same kind (409)."""

    field = "name"
    type = "name_taken"


class RecordDamaged(StoreError):
    """A stored record could not be decoded (500; the rest of the store is fine)."""

    status = 500


@runtime_checkable
class Store(Protocol):
    """The store interface of the service (thread-safe implementations)."""

    def put_fit(
        self,
        record: FitRecord,
        save: bool = True,
        expected_version: int | None = None,
        nk: dict[str, list[float]] | None = None,
    ) -> FitRecord:
        """
        Save ``record`` unless its id exists, and log the save (the fit
        becomes its material's latest, the material's version one more);
        return the stored record. With ``save`` False (a draft) the record
        is stored but not logged: it is reachable by id and lists under no
        material until saved. With ``expected_version`` (0: a material not
        saved yet) the save is refused with :class:`StoreConflict` unless
        the material is at that version now, or its latest fit already is
        this record (a retried save: answered, not logged again). With
        ``nk`` (``{"wavelength_nm", "n", "k"}``) the n, k record
        ``record.nk_id`` is stored too, in the same transaction, unless it
        exists: an n, k record lives as long as a fit refers to it (a saved
        one: always; drafts: until they expire, :meth:`expire_drafts`).
        """

    def set_metrics(self, fit_id: str, metrics: dict[str, Any]) -> FitRecord | None:
        """
        Give the stored fit ``fit_id`` its ``metrics`` (a fit's metrics are
        evaluated after it is saved, :mod:`service.jobs.evaluation`; the rest
        of the record never changes); the record as stored now, or None when
        it is not stored.
        """

    def get_nk(self, nk_id: str) -> dict[str, list[float]] | None:
        """The n, k record ``nk_id`` (``{"wavelength_nm", "n", "k"}``), or None (never stored, or expired)."""

    def get_fit(self, fit_id: str) -> FitRecord | None:
        """The record of ``fit_id``, or None."""

    def latest_fit(self, material_id: str) -> FitRecord | None:
        """The fit of a material saved last, or None."""

    def saved_materials(self) -> list[MaterialRow]:
        """Materials with at least one non-library fit, oldest first."""

    def material_page(
        self,
        after: int | None,
        limit: int,
        kinds: tuple[str, ...] = ("nk", "curves"),
        deleted: bool = False,
        query: str | None = None,
    ) -> MaterialPage:
        """
        Saved materials of ``kinds`` after cursor ``after`` (None: from the
        first), at most ``limit``: those not deleted, or (``deleted``) only
        those deleted; with ``query``, only those whose name or source
        holds it (case-insensitive for ASCII letters).
        """

    def material(self, material_id: str) -> MaterialRow | None:
        """The summary row of a saved material (deleted or not), or None."""

    def find_material(self, kind: str, name: str) -> str | None:
        """The id of the material of ``kind`` called ``name`` now (one not deleted first), or None."""

    def name_clash(self, name: str, material_id: str) -> str | None:
        """
        Why a save of ``material_id`` under ``name`` would now be refused
        (:class:`NameTaken`: another edited material's name looks the same),
        or None: the save's rule read ahead, so that a refused save costs no fit.
        """

    def rename_material(self, material_id: str, name: str) -> MaterialRow:
        """
        Call a saved material ``name`` (not a save: its version is kept);
        :class:`NameTaken` when another material of kind ``curves`` is
        called that, ``LookupError`` when not saved, ``ValueError`` for a
        library material.
        """

    def delete_material(self, material_id: str) -> MaterialRow:
        """
        Move a saved material to the bin (a soft delete: listed only with
        ``deleted``, its fits and saves kept, :meth:`restore_material`
        undoes it; a later save of it restores it too). Idempotent.
        """

    def restore_material(self, material_id: str) -> MaterialRow:
        """Take a material out of the bin. Idempotent."""

    def material_versions(self, material_id: str, before: int | None, limit: int) -> list[VersionRow]:
        """A material's saves with version below ``before`` (None: all), newest first, at most ``limit``."""

    def version_fit(self, material_id: str, version: int) -> FitRecord | None:
        """The fit saved as ``version`` of a material (1: the first save), or None."""

    def latest_fit_ids(self, material_ids: list[str]) -> dict[str, str]:
        """The latest fit id of each of ``material_ids`` that has one."""

    def material_version(self, material_id: str) -> int:
        """The number of saves of a material (0: never saved)."""

    def expire_drafts(self, older_than: float, max_bytes: int) -> int:
        """
        Remove drafts (fits never saved, nor a saved fit's base, nor the
        base of such a base) created before ``older_than`` (a
        ``time.time()``) unless a link keeps them till now or later
        (:meth:`keep_draft`), then the oldest drafts until all left hold at
        most ``max_bytes`` of records (those a link keeps last; each n, k
        record counted once, with the newest draft that refers to it), then
        the n, k records no fit refers to any more; return how many drafts
        were removed.
        """

    def keep_draft(self, fit_id: str, until: float) -> float | None:
        """
        Keep the draft ``fit_id`` at least until ``until`` (a link to it
        was made); return when it expires, None when it never does (a saved
        fit, or a saved fit's base); ``LookupError`` when it is not stored.
        """

    def check(self) -> None:
        """Raise :class:`StoreError` if the store is unusable or damaged."""

    def ping(self) -> None:
        """A cheap read (no integrity scan): raise :class:`StoreError` if the store cannot answer."""

    def describe(self) -> dict[str, Any]:
        """What ``/healthz`` reports of the store: ``kind``, ``schema_version``, connections."""

    def writable(self) -> str | None:
        """
        None when a save can be written now, else why not (cheap; no write);
        raises :class:`StoreUnavailable` when the store cannot be reached.
        """

    def close(self) -> None:
        """Release connections."""
