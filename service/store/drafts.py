"""
Drafts kept and swept, once for both dialects
=============================================

The drafts (fits no save refers to: an editor's unsaved refits) as
functions of an open DB-API connection and its placeholder (as
:mod:`service.store.queries`):

-   :func:`keep_draft`: a draft kept at least until a time (a link to it
    was made).
-   :func:`expire_drafts`: the drafts' sweep (age, then quota, then the
    n, k records no fit refers to).
"""

from __future__ import annotations

import time
from typing import Any

__all__ = ["keep_draft", "expire_drafts"]


_KEPT_BASES = (
    "WITH RECURSIVE kept(id) AS (SELECT f.base_fit_id FROM fits f JOIN saves s ON s.fit_id = f.id "
    "WHERE f.base_fit_id IS NOT NULL UNION SELECT f.base_fit_id FROM fits f JOIN kept ON f.id = kept.id "
    "WHERE f.base_fit_id IS NOT NULL)"
)
"""The fits a saved fit starts from, and those these start from, to any depth: never swept."""


def keep_draft(connection: Any, p: str, fit_id: str, until: float) -> float | None:
    """
    Inside a write transaction: keep the draft ``fit_id`` at least until
    ``until`` (a link to it was made) and return when it expires; None for
    a saved fit or a saved fit's base (never swept); ``LookupError`` when
    there is no such fit.
    """
    found = connection.execute(
        f"{_KEPT_BASES} SELECT EXISTS (SELECT 1 FROM saves WHERE saves.fit_id = fits.id) "
        f"OR id IN (SELECT id FROM kept), coalesce(kept_until, 0) FROM fits WHERE id = {p}",
        (fit_id,),
    ).fetchone()
    if found is None:
        raise LookupError(f"fit {fit_id!r} not found (a draft is kept only for its time to live)")
    if found[0]:
        return None
    until = max(until, float(found[1]))
    connection.execute(f"UPDATE fits SET kept_until = {p} WHERE id = {p}", (until, fit_id))
    return until


def expire_drafts(connection: Any, p: str, older_than: float, max_bytes: int) -> int:
    """
    Inside one write transaction that holds the saves' lock: remove the
    drafts (records no save refers to, nor a saved fit as its base, nor a
    draft so kept as its base: :data:`_KEPT_BASES`) created before
    ``older_than`` and not kept by a link (:func:`keep_draft`) till now or
    later, then the oldest drafts until those left hold at most
    ``max_bytes`` (those a link keeps last; a draft's n, k record counted
    once, with the newest draft that refers to it), then the n, k records
    no fit refers to; return how many drafts were removed.
    """
    now = time.time()
    rows = connection.execute(
        f"{_KEPT_BASES} SELECT id, created_at, length(record), nk_id, coalesce(kept_until, 0) FROM fits "
        "WHERE NOT EXISTS (SELECT 1 FROM saves WHERE saves.fit_id = fits.id) AND id NOT IN (SELECT id FROM kept) "
        "ORDER BY created_at DESC"
    ).fetchall()
    # Drafts a link keeps come first: past the quota, the others go before them.
    rows.sort(key=lambda row: row[4] < now)
    nk_sizes = dict(connection.execute("SELECT id, length(record) FROM nk_records").fetchall())
    kept, doomed, counted = 0, [], set()
    for fit_id, created_at, size, nk_id, until in rows:  # newest first: the oldest go past the quota
        size += nk_sizes.get(nk_id, 0) if nk_id not in counted else 0
        if (created_at < older_than and until < now) or kept + size > max_bytes:
            doomed.append((fit_id,))
        else:
            kept += size
            counted.add(nk_id)
    if doomed:
        # A cursor's: psycopg's connection has no executemany (the sweep failed on PostgreSQL).
        connection.cursor().executemany(f"DELETE FROM fits WHERE id = {p}", doomed)
    connection.execute("DELETE FROM nk_records WHERE NOT EXISTS (SELECT 1 FROM fits WHERE fits.nk_id = nk_records.id)")
    return len(doomed)
