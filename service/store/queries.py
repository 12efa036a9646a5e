"""
The store's queries, once for both dialects
===========================================

Every read and write of the store as a function of an open DB-API
connection (``sqlite3`` or ``psycopg``) and its placeholder (``?`` or
``%s``): the SQL both stores run is the same text, so the two cannot drift.
The caller owns the transaction and translates driver errors.

-   :func:`save`: the body of ``put_fit`` (write-once record, save log,
    summary row, the expected-version check).
-   :func:`expire_drafts`: the drafts' sweep (age, then quota).
-   :func:`get_text`, :func:`latest_texts`, :func:`latest_ids`,
    :func:`version_of`, :func:`page_rows`, :func:`page_of`: the reads.
"""

from __future__ import annotations

import logging
import time
from typing import Any, Callable

from .migrations import UPSERT_MATERIAL
from .records import FIT_KINDS, FitRecord, MaterialPage, MaterialRow, StoreConflict

__all__ = ["save", "get_text", "latest_texts", "latest_ids", "version_of", "page_rows", "page_of",
           "expire_drafts"]

log = logging.getLogger("service.store")


def save(connection: Any, p: str, record: FitRecord, text: str, save: bool,
         expected_version: int | None, decode: Callable[[str, Any], FitRecord]) -> FitRecord:
    """
    Inside one open write transaction (which the caller serialises with
    every other save): store ``record`` unless its id exists, then (``save``)
    check ``expected_version`` and log the save. Returns the stored record.
    """
    connection.execute(
        f"INSERT INTO fits (id, kind, material_id, created_at, record) VALUES ({p}, {p}, {p}, {p}, {p}) "
        "ON CONFLICT (id) DO NOTHING",
        (record.id, record.kind, record.material_id, record.created_at, text))
    stored = decode(record.id, get_text(connection, p, record.id))
    if not save:  # a draft: stored, reachable by id, listed under no material
        return stored
    if expected_version is not None:
        row = connection.execute(
            f"SELECT version, latest_fit_id FROM materials WHERE material_id = {p}",
            (stored.material_id,)).fetchone()
        version, latest = (int(row[0]), row[1]) if row else (0, None)
        if version != expected_version:
            if latest == stored.id and version == expected_version + 1:
                return stored  # this very save, retried: answered, not logged twice
            raise StoreConflict(
                f"material {stored.name!r} ({stored.material_id}) is at version {version}"
                + (f" (latest fit {latest})" if latest else "")
                + f", not the expected version {expected_version}: another save came first; "
                "reload it and save again with `expected_version` "
                f"{version}", version=version, latest_fit_id=latest)
    now = time.time()
    (seq,) = connection.execute(
        f"INSERT INTO saves (material_id, fit_id, saved_at) VALUES ({p}, {p}, {p}) RETURNING seq",
        (stored.material_id, stored.id, now)).fetchone()
    connection.execute(UPSERT_MATERIAL.format(p=p), (
        stored.material_id, seq, now, stored.id, stored.kind, _text(stored.name), _text(stored.source),
        stored.coverage))
    return stored


def _text(value: str) -> str:
    """A summary's text column: NUL (which PostgreSQL text refuses) shown as U+FFFD; the record keeps it."""
    return value.replace("\x00", "\ufffd")


def get_text(connection: Any, p: str, fit_id: str) -> Any:
    """The stored JSON text of ``fit_id``, or None."""
    row = connection.execute(f"SELECT record FROM fits WHERE id = {p}", (fit_id,)).fetchone()
    return None if row is None else row[0]


def latest_texts(connection: Any, p: str, material_id: str) -> list[tuple[str, Any]]:
    """(fit id, JSON text) of a material's last 16 saves, the latest first."""
    return connection.execute(
        f"SELECT f.id, f.record FROM saves s JOIN fits f ON f.id = s.fit_id "
        f"WHERE s.material_id = {p} ORDER BY s.seq DESC LIMIT 16", (material_id,)).fetchall()


def latest_ids(connection: Any, p: str, material_ids: list[str]) -> dict[str, str]:
    """The latest fit id of each of ``material_ids`` that has one."""
    if not material_ids:
        return {}
    marks = ",".join([p] * len(material_ids))
    return dict(connection.execute(
        f"SELECT material_id, latest_fit_id FROM materials WHERE material_id IN ({marks})",
        list(material_ids)).fetchall())


def version_of(connection: Any, p: str, material_id: str) -> int:
    """The number of saves of ``material_id`` (0: never saved)."""
    row = connection.execute(f"SELECT version FROM materials WHERE material_id = {p}",
                             (material_id,)).fetchone()
    return 0 if row is None else int(row[0])


def page_rows(connection: Any, p: str, after: int | None, limit: int) -> list[tuple]:
    """Summary rows of saved (non-library) materials after cursor ``after``, one more than ``limit``."""
    return connection.execute(
        "SELECT material_id, name, source, coverage, kind, latest_fit_id, first_saved_at, "
        f"first_seq, version FROM materials WHERE kind != 'library' AND first_seq > {p} "
        f"ORDER BY first_seq LIMIT {p}", (after or 0, limit + 1)).fetchall()


def page_of(rows: list[tuple], limit: int) -> MaterialPage:
    """A :class:`MaterialPage` of :func:`page_rows`; unreadable summaries are named in ``skipped``."""
    out, skipped = [], []
    for material_id, name, source, coverage, kind, latest, first_at, seq, version in rows[:limit]:
        if (kind not in FIT_KINDS or not isinstance(name, str) or not isinstance(source, str)
                or not (coverage is None or isinstance(coverage, float))):
            log.error("the summary of material %r cannot be read, skipped", material_id)
            skipped.append(str(material_id))
            continue
        out.append(MaterialRow(material_id=material_id, name=name, source=source,
                               coverage=coverage, kind=kind, latest_fit_id=latest,
                               created_at=first_at, seq=int(seq), version=int(version)))
    next_cursor = int(rows[limit - 1][7]) if len(rows) > limit else None
    return MaterialPage(out, next_cursor, skipped)


def expire_drafts(connection: Any, p: str, older_than: float, max_bytes: int) -> int:
    """
    Inside one write transaction that holds the saves' lock: remove the
    drafts (records no save refers to) created before ``older_than``, then
    the oldest drafts until those left hold at most ``max_bytes``; return
    how many were removed.
    """
    rows = connection.execute(
        "SELECT id, created_at, length(record) FROM fits WHERE NOT EXISTS "
        "(SELECT 1 FROM saves WHERE saves.fit_id = fits.id) ORDER BY created_at DESC").fetchall()
    kept, doomed = 0, []
    for fit_id, created_at, size in rows:  # newest first: the oldest go past the quota
        if created_at < older_than or kept + size > max_bytes:
            doomed.append((fit_id,))
        else:
            kept += size
    if doomed:
        connection.executemany(f"DELETE FROM fits WHERE id = {p}", doomed)
    return len(doomed)
