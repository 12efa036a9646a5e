"""
The SQL both stores share
=========================

:class:`SQLStore`: every method of :class:`service.store.Store` that is
the same SQL on SQLite and on PostgreSQL (:mod:`service.store.queries`,
written once with the driver's placeholder), over three hooks a backend
gives: :attr:`SQLStore.placeholder` (``?`` or ``%s``), :meth:`SQLStore._read`
(a function of a connection in one transaction, errors as
:class:`StoreError`) and :meth:`SQLStore._write` (the same, holding the lock
the saves take). A backend adds its connections, its saves (``put_fit``,
whose locking differs), its checks and its own state; the contract suite
(``tests/service/test_store.py``, run on both) holds them to one behaviour.
"""

from __future__ import annotations

import logging
from typing import Any, Callable, TypeVar

from . import drafts, material_edits, queries, records
from .records import FitRecord, MaterialPage, MaterialRow, RecordDamaged, VersionRow

__all__ = ["SQLStore"]

log = logging.getLogger("service.store")
_T = TypeVar("_T")


class SQLStore:
    """The shared part of :class:`SQLiteStore` and :class:`PostgresStore` (see the module docstring)."""

    placeholder: str
    """The driver's query placeholder (``?`` for sqlite3, ``%s`` for psycopg)."""

    def _read(self, function: Callable[[Any], _T]) -> _T:
        """``function(connection)`` in one transaction; the driver's errors as :class:`StoreError`."""
        raise NotImplementedError

    def _write(self, function: Callable[[Any], _T]) -> _T:
        """``function(connection)`` in one transaction holding the lock every save takes."""
        raise NotImplementedError

    def _decode(self, fit_id: str, text: Any) -> FitRecord:
        try:
            return FitRecord.from_json(text)
        except (TypeError, ValueError) as error:
            log.error("stored fit %s cannot be decoded: %s", fit_id, error)
            raise RecordDamaged(
                f"the stored record of fit {fit_id} is damaged and cannot be read; the rest of the store is unaffected"
            ) from None

    def _decoded(self, fit_id: str, text: Any) -> FitRecord | None:
        try:
            return self._decode(fit_id, text)
        except RecordDamaged:
            return None

    # -- the interface -----------------------------------------------------

    def set_metrics(self, fit_id: str, metrics: dict[str, Any]) -> FitRecord | None:
        return self._write(lambda c: queries.set_metrics(c, self.placeholder, fit_id, metrics, self._decode))

    def get_nk(self, nk_id: str) -> dict[str, list[float]] | None:
        text = self._read(lambda c: queries.get_nk(c, self.placeholder, nk_id))
        return None if text is None else records.nk_from_json(nk_id, text)

    def expire_drafts(self, older_than: float, max_bytes: int) -> int:
        # Under the saves' lock: no save is half done while the sweep runs.
        return self._write(lambda c: drafts.expire_drafts(c, self.placeholder, older_than, max_bytes))

    def keep_draft(self, fit_id: str, until: float) -> float | None:
        return self._write(lambda c: drafts.keep_draft(c, self.placeholder, fit_id, until))

    def get_fit(self, fit_id: str) -> FitRecord | None:
        text = self._read(lambda c: queries.get_text(c, self.placeholder, fit_id))
        return None if text is None else self._decode(fit_id, text)

    def latest_fit(self, material_id: str) -> FitRecord | None:
        """The latest decodable fit of a material (a damaged one is logged and passed over)."""
        for fit_id, text in self._read(lambda c: queries.latest_texts(c, self.placeholder, material_id)):
            try:
                return self._decode(fit_id, text)
            except RecordDamaged:
                continue
        return None

    def latest_fit_ids(self, material_ids: list[str]) -> dict[str, str]:
        return self._read(lambda c: queries.latest_ids(c, self.placeholder, material_ids))

    def material_version(self, material_id: str) -> int:
        return self._read(lambda c: queries.version_of(c, self.placeholder, material_id))

    def material_page(
        self,
        after: int | None,
        limit: int,
        kinds: tuple[str, ...] = queries.LISTED_KINDS,
        deleted: bool = False,
        query: str | None = None,
    ) -> MaterialPage:
        return queries.page_of(
            self._read(lambda c: queries.page_rows(c, self.placeholder, after, limit, kinds, deleted, query)), limit
        )

    def material(self, material_id: str) -> MaterialRow | None:
        return self._read(lambda c: queries.material_row(c, self.placeholder, material_id))

    def find_material(self, kind: str, name: str) -> str | None:
        return self._read(lambda c: queries.find_material(c, self.placeholder, kind, name))

    def name_clash(self, name: str, material_id: str) -> str | None:
        return self._read(lambda c: material_edits.look_alike_clash(c, self.placeholder, name, material_id))

    def rename_material(self, material_id: str, name: str) -> MaterialRow:
        return self._write(lambda c: material_edits.rename(c, self.placeholder, material_id, name))

    def delete_material(self, material_id: str) -> MaterialRow:
        return self._write(lambda c: material_edits.set_deleted(c, self.placeholder, material_id, True))

    def restore_material(self, material_id: str) -> MaterialRow:
        return self._write(lambda c: material_edits.set_deleted(c, self.placeholder, material_id, False))

    def material_versions(self, material_id: str, before: int | None, limit: int) -> list[VersionRow]:
        rows = self._read(lambda c: queries.version_texts(c, self.placeholder, material_id, before, limit))
        return [VersionRow(v, fit_id, saved_at, self._decoded(fit_id, text)) for v, fit_id, saved_at, text in rows]

    def version_fit(self, material_id: str, version: int) -> FitRecord | None:
        row = self._read(lambda c: queries.version_text(c, self.placeholder, material_id, version))
        return None if row is None else self._decode(*row)

    def saved_materials(self) -> list[MaterialRow]:
        rows: list[MaterialRow] = []
        cursor = None
        while True:
            page = self.material_page(cursor, 1000)
            rows.extend(page.rows)
            if page.next_cursor is None:
                return rows
            cursor = page.next_cursor
