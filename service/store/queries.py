"""
The store's queries, once for both dialects
===========================================

Every read and write of the store as a function of an open DB-API
connection (``sqlite3`` or ``psycopg``) and its placeholder (``?`` or
``%s``): the SQL both stores run is the same text, so the two cannot drift.
The caller owns the transaction and translates driver errors.

-   :func:`save`: the body of ``put_fit`` (write-once record, save log,
    summary row, the expected-version check).
-   :func:`set_metrics`: a stored fit's metrics, evaluated after it was saved.
-   :func:`get_nk`: an n, k record.
-   :func:`get_text`, :func:`latest_texts`, :func:`latest_ids`,
    :func:`version_of`, :func:`page_rows`, :func:`page_of`,
    :func:`material_row`, :func:`find_material`, :func:`version_texts`,
    :func:`version_text`: the reads.

The drafts' sweep is :mod:`service.store.drafts`; renames and the bin are
:mod:`service.store.material_edits`.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from typing import Any, Callable

from .migrations import UPSERT_MATERIAL
from .names import name_key
from .records import FIT_KINDS, FitRecord, MaterialPage, MaterialRow, NameTaken, StoreConflict, StoreFull

INT64_MAX = 2**63 - 1
MAX_VERSIONS_PER_MATERIAL = 10_000
"""The most versions one material keeps; a save past them is refused (507): its history is bounded."""

__all__ = [
    "save",
    "set_metrics",
    "get_nk",
    "get_text",
    "latest_texts",
    "latest_ids",
    "version_of",
    "page_rows",
    "page_of",
    "material_row",
    "find_material",
    "version_texts",
    "version_text",
    "summary_text",
    "other_name_holder",
    "name_clash_message",
    "check_expected",
    "LISTED_KINDS",
]

log = logging.getLogger("service.store")


def save(
    connection: Any,
    p: str,
    record: FitRecord,
    text: str,
    save: bool,
    expected_version: int | None,
    decode: Callable[[str, Any], FitRecord],
    nk_json: Callable[[], str] | None = None,
) -> FitRecord:
    """
    Inside one open write transaction (which the caller serialises with
    every other save, and with the drafts' sweep when ``nk_json`` is given):
    store the n, k record ``record.nk_id`` (``nk_json()``, its JSON, made
    only then) unless it exists, and ``record`` unless its id exists, then
    (``save``) check ``expected_version`` and log the save. Returns the
    stored record.
    """
    if (
        nk_json is not None
        and connection.execute(f"SELECT 1 FROM nk_records WHERE id = {p}", (record.nk_id,)).fetchone() is None
    ):
        connection.execute(
            f"INSERT INTO nk_records (id, created_at, record) VALUES ({p}, {p}, {p}) ON CONFLICT (id) DO NOTHING",
            (record.nk_id, record.created_at, nk_json()),
        )
    connection.execute(
        f"INSERT INTO fits (id, kind, material_id, created_at, record, nk_id, base_fit_id) "
        f"VALUES ({p}, {p}, {p}, {p}, {p}, {p}, {p}) ON CONFLICT (id) DO NOTHING",
        (record.id, record.kind, record.material_id, record.created_at, text, record.nk_id, record.base_fit_id),
    )
    stored = decode(record.id, get_text(connection, p, record.id))
    if not save:  # a draft: stored, reachable by id, listed under no material
        return stored
    row = material_row(connection, p, stored.material_id)
    if (
        row is not None
        and row.latest_fit_id == stored.id
        and row.deleted_at is None
        and row.name == summary_text(stored.name)
    ):
        return stored  # nothing changed (a repeat, or this very save retried): no new version
    check_expected(row, stored.material_id, stored.name, expected_version)
    if row is not None and row.version >= MAX_VERSIONS_PER_MATERIAL:
        raise StoreFull(
            f"material {stored.name!r} ({stored.material_id}) has {row.version} versions, the most "
            f"one material keeps ({MAX_VERSIONS_PER_MATERIAL}); save it under another name"
        )
    if stored.kind == "curves":
        # An edited material is found by its name: another one given this name
        # since the save chose its material (a rename at the same moment) wins.
        # A look-alike of another's name is refused when the name is new to
        # this material (two look-alikes saved before keys existed both stay saveable).
        holder = other_name_holder(connection, p, stored.name, stored.material_id)
        version, latest = (row.version, row.latest_fit_id) if row else (0, None)
        if holder is not None and holder[2] != summary_text(stored.name):
            if row is None or row.name != summary_text(stored.name):
                raise NameTaken(name_clash_message(stored.name, holder), version=version, latest_fit_id=latest)
        elif holder is not None:
            raise NameTaken(
                f"`name` {stored.name!r} was just given to another saved material {holder[0]}: "
                "save again (the save then goes to that material), or choose another name",
                version=version,
                latest_fit_id=latest,
            )
    now = time.time()
    (seq,) = connection.execute(
        f"INSERT INTO saves (material_id, fit_id, saved_at) VALUES ({p}, {p}, {p}) RETURNING seq",
        (stored.material_id, stored.id, now),
    ).fetchone()
    connection.execute(
        UPSERT_MATERIAL.format(p=p),
        (
            stored.material_id,
            seq,
            now,
            stored.id,
            stored.kind,
            summary_text(stored.name),
            summary_text(stored.source),
            stored.coverage,
            name_key(stored.name),
        ),
    )
    return stored


def check_expected(
    row: MaterialRow | None, material_id: str, name: str, expected_version: int | None, done: str = "nothing was saved"
) -> None:
    """
    Raise :class:`StoreConflict` (409) when a save that names
    ``expected_version`` would undo what changed since that version: another
    save (the version moved on), a rename (the save still carries the old
    ``name``) or a delete (the material is in the bin; a save expecting a
    version does not take it out). ``row``: the material's summary now.
    """
    if expected_version is None:
        return
    version, latest = (row.version, row.latest_fit_id) if row else (0, None)
    now = f"material {name!r} ({material_id})"
    if version != expected_version:
        raise StoreConflict(
            f"{now} is at version {version}"
            + (f" (latest fit {latest})" if latest else "")
            + f", not the expected version {expected_version}: another save came first; {done}; "
            f"reload it and save again with `expected_version` {version}",
            version=version,
            latest_fit_id=latest,
        )
    if row is None:
        return
    if row.kind == "curves" and row.name != summary_text(name):
        raise StoreConflict(
            f"{now} was renamed {row.name!r} since version {version} was read: {done}; reopen it, "
            f"or save it with `name` {row.name!r}",
            version=version,
            latest_fit_id=latest,
        )
    if row.deleted_at is not None:
        raise StoreConflict(
            f"{now} was moved to the bin at {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime(row.deleted_at))}"
            f": {done}; restore it first (`POST /api/v1/materials/{material_id}/restore`), or save "
            "without `expected_version` to restore it with the save",
            version=version,
            latest_fit_id=latest,
        )


def summary_text(value: str) -> str:
    """A summary's text column: NUL (which PostgreSQL text refuses) shown as U+FFFD; the record keeps it."""
    return value.replace("\x00", "\ufffd")


def get_nk(connection: Any, p: str, nk_id: str) -> Any:
    """The stored JSON text of the n, k record ``nk_id``, or None."""
    row = connection.execute(f"SELECT record FROM nk_records WHERE id = {p}", (nk_id,)).fetchone()
    return None if row is None else row[0]


def set_metrics(
    connection: Any, p: str, fit_id: str, metrics: dict[str, Any], decode: Callable[[str, Any], FitRecord]
) -> FitRecord | None:
    """
    Replace the metrics of the stored fit ``fit_id`` (the rest of its record
    stays as written); the record as stored now, or None when it is not
    stored (an expired draft).
    """
    text = get_text(connection, p, fit_id)
    if text is None:
        return None
    record = dataclasses.replace(decode(fit_id, text), metrics=metrics)
    connection.execute(f"UPDATE fits SET record = {p} WHERE id = {p}", (record.to_json(), fit_id))
    return record


def get_text(connection: Any, p: str, fit_id: str) -> Any:
    """The stored JSON text of ``fit_id``, or None."""
    row = connection.execute(f"SELECT record FROM fits WHERE id = {p}", (fit_id,)).fetchone()
    return None if row is None else row[0]


def latest_texts(connection: Any, p: str, material_id: str) -> list[tuple[str, Any]]:
    """(fit id, JSON text) of a material's last 16 saves, the latest first."""
    return connection.execute(
        f"SELECT f.id, f.record FROM saves s JOIN fits f ON f.id = s.fit_id "
        f"WHERE s.material_id = {p} ORDER BY s.seq DESC LIMIT 16",
        (material_id,),
    ).fetchall()


def latest_ids(connection: Any, p: str, material_ids: list[str]) -> dict[str, str]:
    """The latest fit id of each of ``material_ids`` that has one."""
    if not material_ids:
        return {}
    marks = ",".join([p] * len(material_ids))
    return dict(
        connection.execute(
            f"SELECT material_id, latest_fit_id FROM materials WHERE material_id IN ({marks})", list(material_ids)
        ).fetchall()
    )


def version_of(connection: Any, p: str, material_id: str) -> int:
    """The number of saves of ``material_id`` (0: never saved)."""
    row = connection.execute(f"SELECT version FROM materials WHERE material_id = {p}", (material_id,)).fetchone()
    return 0 if row is None else int(row[0])


LISTED_KINDS = ("nk", "curves")
"""The kinds of saved materials a page lists by default (library fits are listed by the route)."""
_ROW = "material_id, name, source, coverage, kind, latest_fit_id, first_saved_at, first_seq, version, deleted_at"


def _like(text: str) -> str:
    """``text`` as a LIKE pattern that matches it anywhere, its ``%``, ``_`` and ``\\`` literal."""
    escaped = text.lower().replace("\\", "\\\\").replace("%", "\\%").replace("_", "\\_")
    return f"%{escaped}%"


def page_rows(
    connection: Any,
    p: str,
    after: int | None,
    limit: int,
    kinds: tuple[str, ...] = LISTED_KINDS,
    deleted: bool = False,
    query: str | None = None,
) -> list[tuple]:
    """
    Summary rows of saved materials of ``kinds`` after cursor ``after``,
    one more than ``limit``: those not in the bin (or, ``deleted``, only
    those in it), with ``query`` only those whose name or source holds it.
    """
    # The kinds not asked for are left out, so a row of an unreadable kind is still read
    # (and reported in ``skipped`` by page_of) whatever was asked for.
    left_out = ("library", *(k for k in FIT_KINDS if k != "library" and k not in kinds))
    where = [
        f"kind NOT IN ({','.join([p] * len(left_out))})",
        f"first_seq > {p}",
        "deleted_at IS NOT NULL" if deleted else "deleted_at IS NULL",
    ]
    params: list[Any] = [*left_out, after or 0]
    if query:
        where.append(f"(lower(name) LIKE {p} ESCAPE '\\' OR lower(source) LIKE {p} ESCAPE '\\')")
        params += [_like(query), _like(query)]
    return connection.execute(
        f"SELECT {_ROW} FROM materials WHERE {' AND '.join(where)} ORDER BY first_seq LIMIT {p}", (*params, limit + 1)
    ).fetchall()


def _row(values: tuple) -> MaterialRow | None:
    """A :class:`MaterialRow` of one summary row, None when it cannot be read (logged)."""
    material_id, name, source, coverage, kind, latest, first_at, seq, version, deleted_at = values
    if (
        kind not in FIT_KINDS
        or not isinstance(name, str)
        or not isinstance(source, str)
        or not (coverage is None or isinstance(coverage, float))
    ):
        log.error("the summary of material %r cannot be read, skipped", material_id)
        return None
    return MaterialRow(
        material_id=material_id,
        name=name,
        source=source,
        coverage=coverage,
        kind=kind,
        latest_fit_id=latest,
        created_at=first_at,
        seq=int(seq),
        version=int(version),
        deleted_at=None if deleted_at is None else float(deleted_at),
    )


def page_of(rows: list[tuple], limit: int) -> MaterialPage:
    """A :class:`MaterialPage` of :func:`page_rows`; unreadable summaries are named in ``skipped``."""
    out, skipped = [], []
    for values in rows[:limit]:
        row = _row(values)
        if row is None:
            skipped.append(str(values[0]))
        else:
            out.append(row)
    next_cursor = int(rows[limit - 1][7]) if len(rows) > limit else None
    return MaterialPage(out, next_cursor, skipped)


def material_row(connection: Any, p: str, material_id: str) -> MaterialRow | None:
    """The summary row of ``material_id`` (in the bin or not), or None."""
    values = connection.execute(f"SELECT {_ROW} FROM materials WHERE material_id = {p}", (material_id,)).fetchone()
    return None if values is None else _row(values)


def find_material(connection: Any, p: str, kind: str, name: str) -> str | None:
    """The id of the material of ``kind`` called ``name`` (one not in the bin first), or None."""
    row = connection.execute(
        f"SELECT material_id FROM materials WHERE kind = {p} AND name = {p} "
        "ORDER BY (deleted_at IS NOT NULL), first_seq LIMIT 1",
        (kind, summary_text(name)),
    ).fetchone()
    return None if row is None else row[0]


def other_name_holder(connection: Any, p: str, name: str, material_id: str):
    """
    (id, deleted_at, name) of an edited material other than ``material_id``
    (in the bin or not) whose name is ``name`` or looks the same
    (:func:`service.store.names.name_key`), the one called ``name`` first; or None.
    """
    return connection.execute(
        f"SELECT material_id, deleted_at, name FROM materials WHERE kind = 'curves' "
        f"AND (name = {p} OR name_key = {p}) AND material_id != {p} "
        f"ORDER BY (name = {p}) DESC, first_seq LIMIT 1",
        (summary_text(name), name_key(name), material_id, summary_text(name)),
    ).fetchone()


def name_clash_message(name: str, holder: tuple) -> str:
    """The message of a name that looks the same as another material's (``holder``: :func:`other_name_holder`'s)."""
    where = " (in the bin)" if holder[1] is not None else ""
    return (
        f"`name` {name!r} looks the same as {holder[2]!r}, the name of saved material {holder[0]}{where} "
        "(the same letters up to case, width and look-alike characters: the same Unicode TR39 skeleton); "
        f"save to that material under {holder[2]!r}, or choose another name"
    )


_VERSIONS = "(SELECT ROW_NUMBER() OVER (ORDER BY seq) AS v, fit_id, saved_at FROM saves WHERE material_id = {p}) t"


def version_texts(connection: Any, p: str, material_id: str, before: int | None, limit: int) -> list[tuple]:
    """(version, fit id, saved at, JSON text) of a material's saves below ``before``, newest first."""
    return connection.execute(
        f"SELECT t.v, t.fit_id, t.saved_at, f.record FROM {_VERSIONS.format(p=p)} "
        f"JOIN fits f ON f.id = t.fit_id WHERE t.v < {p} ORDER BY t.v DESC LIMIT {p}",
        (material_id, INT64_MAX if before is None else before, limit),
    ).fetchall()


def version_text(connection: Any, p: str, material_id: str, version: int) -> tuple | None:
    """(fit id, JSON text) of version ``version`` of a material, or None."""
    return connection.execute(
        f"SELECT t.fit_id, f.record FROM {_VERSIONS.format(p=p)} JOIN fits f ON f.id = t.fit_id WHERE t.v = {p}",
        (material_id, version),
    ).fetchone()
