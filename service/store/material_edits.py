"""
Renames and the bin, once for both dialects
===========================================

What an artist changes of a saved material, as functions of an open DB-API
connection and its placeholder (as :mod:`service.store.queries`): its
summary row only; records and saves stay as written.

-   :func:`rename`: a material renamed, refused (:class:`NameTaken`) when
    another edited material has that name or one that looks the same.
-   :func:`set_deleted`: a material moved to the bin or out of it.
-   :func:`look_alike_clash`: why a save of ``material_id`` under a name
    would be refused for looking the same as another's (the save's own
    rule, read ahead of its fit), or None.
"""

from __future__ import annotations

import time
from typing import Any

from .names import name_key
from .queries import name_clash_message, other_name_holder, material_row, summary_text
from .records import MaterialRow, NameTaken

__all__ = ["rename", "set_deleted", "look_alike_clash"]


def _saved(connection: Any, p: str, material_id: str) -> MaterialRow:
    """The row of a saved, non-library material: LookupError or ValueError otherwise."""
    row = material_row(connection, p, material_id)
    if row is None:
        raise LookupError(f"`material_id` {material_id!r} is not a saved material")
    if row.kind == "library":
        raise ValueError(f"`material_id` {material_id!r} is a built-in material: it cannot be renamed or deleted")
    return row


def rename(connection: Any, p: str, material_id: str, name: str) -> MaterialRow:
    """Inside a write transaction holding the saves' lock: the summary of ``material_id`` renamed."""
    row = _saved(connection, p, material_id)
    if row.kind == "curves":  # an edited material is found by its name: names are unique
        holder = other_name_holder(connection, p, name, material_id)
        if holder is not None and holder[2] != summary_text(name):
            raise NameTaken(name_clash_message(name, holder), version=row.version, latest_fit_id=row.latest_fit_id)
        if holder is not None:
            where = " (in the bin)" if holder[1] is not None else ""
            raise NameTaken(
                f"`name` {name!r} is the name of another saved material {holder[0]}{where}: "
                "choose another name, or rename that one first",
                version=row.version,
                latest_fit_id=row.latest_fit_id,
            )
    connection.execute(
        f"UPDATE materials SET name = {p}, name_key = {p} WHERE material_id = {p}",
        (summary_text(name), name_key(name), material_id),
    )
    return material_row(connection, p, material_id)


def set_deleted(connection: Any, p: str, material_id: str, deleted: bool) -> MaterialRow:
    """Inside a write transaction: ``material_id`` moved to the bin (``deleted``) or out of it."""
    row = _saved(connection, p, material_id)
    if deleted and row.deleted_at is None:
        connection.execute(f"UPDATE materials SET deleted_at = {p} WHERE material_id = {p}", (time.time(), material_id))
    elif not deleted and row.deleted_at is not None:
        connection.execute(f"UPDATE materials SET deleted_at = NULL WHERE material_id = {p}", (material_id,))
    return material_row(connection, p, material_id)


def look_alike_clash(connection: Any, p: str, name: str, material_id: str) -> str | None:
    """
    The refusal a save of ``material_id`` under ``name`` meets now
    (:func:`service.store.queries.save`'s rule): another edited
    material's name looks the same and ``name`` is new to this material;
    None when the save may go ahead.
    """
    holder = other_name_holder(connection, p, name, material_id)
    if holder is None or holder[2] == summary_text(name):
        return None  # free, or the very name (the save then goes to that material: resolve_material)
    row = material_row(connection, p, material_id)
    if row is not None and row.name == summary_text(name):
        return None
    return name_clash_message(name, holder)
