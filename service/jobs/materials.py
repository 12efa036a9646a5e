"""
Materials an artist manages
===========================

-   :func:`resolve_material`: the material a save of edited curves goes to
    (by the id the editor opened, else by its name; renames kept).
-   :func:`share_url`: the editor's link to a material (``/?material=``).
-   :func:`fit_edit`: what reopens a stored fit in the editor: its base and
    its edited curves (a shareable link's ``?fit=`` or ``?material=``).
"""

from __future__ import annotations

from typing import Any

from ..store import FitRecord, NameTaken, Store
from ..store.queries import summary_text
from .common import content_address, with_measured_nk

__all__ = ["resolve_material", "fit_edit", "share_url"]


def share_url(material_id: str, version: int | None = None) -> str:
    """The editor's link that reopens a material (at one of its versions)."""
    return f"/?material={material_id}" + ("" if version is None else f"&version={version}")


def resolve_material(store: Store, name: str, material_id: str | None = None, saving: bool = False) -> str:
    """
    The material a curve fit called ``name`` belongs to: ``material_id``
    when given (``LookupError`` unless it is a saved edited material;
    :class:`service.store.NameTaken` when another material is called
    ``name``), else the edited material called ``name`` now (a renamed
    material is found by its new name; one in the bin too, which the save
    takes out), else a new one: the content address of the name, or, when
    that id belongs to a material since renamed, the first free
    ``(name, n)``. ``saving``: :class:`service.store.NameTaken` too when
    the save would be refused for a name that looks the same as another's
    (the store's rule, asked before the fit rather than after it).
    """
    material = _resolved(store, name, material_id)
    if saving and (clash := store.name_clash(name, material)) is not None:
        row = store.material(material)
        raise NameTaken(clash, version=0 if row is None else row.version, latest_fit_id=row and row.latest_fit_id)
    return material


def _resolved(store: Store, name: str, material_id: str | None) -> str:
    holder = store.find_material("curves", name)
    if material_id is not None:
        row = store.material(material_id)
        if row is None or row.kind != "curves":
            raise LookupError(f"`material_id` {material_id!r} is not a saved edited material")
        if holder is not None and holder != material_id:
            raise NameTaken(
                f"`name` {name!r} is the name of another saved material {holder}: save "
                f"{material_id} under another name, or rename that one first",
                version=row.version,
                latest_fit_id=row.latest_fit_id,
            )
        return material_id
    if holder is not None:
        return holder
    candidate, n = content_address("edited material", name), 0
    while (row := store.material(candidate)) is not None:
        if row.kind == "curves" and row.name == summary_text(name):
            # Saved under this name since the lookup above (a concurrent first
            # save, here or on another replica): the same material, not a rename.
            return candidate
        n += 1  # renamed away; one step per such rename
        candidate = content_address("edited material", name, n)
    return candidate


def fit_edit(store: Store, record: FitRecord) -> dict[str, Any]:
    """
    What reopens ``record`` in the editor (:class:`service.schemas.FitEdit`):
    for a curve fit its request (the edited curves and settings) with the
    base it started from; for a library or n, k fit, the fit as the base.
    ``name`` and ``material_id`` are the material's now (a renamed material
    is saved again under its new name).
    """
    row = store.material(record.material_id)
    name = row.name if row is not None else record.name
    out = {
        "fit_id": record.id,
        "kind": record.kind,
        "material_id": record.material_id,
        "name": name,
        "version": 0 if row is None else row.version,
    }
    if record.kind != "curves":
        base = {"material": record.library_material} if record.kind == "library" else {"fit": record.id}
        return {**out, "base": base, "request": None}
    provenance = record.provenance or {}
    spec = provenance.get("base") or None
    if record.base_fit_id is not None:
        base = {"fit": record.base_fit_id}
    elif spec is not None and spec.get("library_material"):
        base = {"material": spec["library_material"]}
    elif spec is not None:  # inline n, k: the record keeps them (a draft: its holder does)
        nk = with_measured_nk(store, record).nk
        base = None if nk is None else {"nk": nk}
    else:
        base = None
    request = {
        key: value
        for key, value in (provenance.get("request") or {}).items()
        if key not in ("draft", "live", "start_fit", "expected_version")
    }
    request.update(name=name, material_id=record.material_id, base=base)
    return {**out, "base": base, "request": request}
