"""
What every job shares
=====================

-   :data:`FIT_FORMAT_VERSION`: part of every id.
-   :func:`content_address`: an id from an unambiguous encoding of parts.
-   :func:`check_finite`: refuse a result holding NaN or infinity.
-   :func:`measured_nk`: the n, k behind a stored fit, if any.
-   :func:`nk_view`: a :class:`fitting.optics.nk.SpectralNK` as the record's lists.
-   :func:`stored_fit`: a stored fit or ``LookupError``, with its n, k.
-   :func:`with_measured_nk`, :func:`nk_holder`, :func:`nk_record_id`,
    :func:`draft_nk_reference`: a draft refers to the record holding its
    n, k (``provenance.nk_of``), or to its n, k stored once as an n, k
    record (``nk_id``), instead of a copy.
-   :func:`fit_record`: the record of a finished job.
-   :func:`checked_writable`: refuse (:class:`service.store.StoreError`)
    before any CPU is spent when the store cannot take the save.
-   :func:`checked_version`: refuse (:class:`service.store.StoreConflict`)
    before any CPU is spent a save that expects another version, name or
    a material not in the bin.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

from fitting.optics.catalogue import catalogue_material
from fitting.optics.nk import SpectralNK

from ..ids import content_address
from ..store import FitRecord, Store, StoreFull, StoreUnavailable
from ..store.queries import check_expected

__all__ = [
    "FIT_FORMAT_VERSION",
    "content_address",
    "check_finite",
    "measured_nk",
    "nk_view",
    "stored_fit",
    "with_measured_nk",
    "nk_holder",
    "nk_record_id",
    "draft_nk_reference",
    "fit_record",
    "checked_writable",
    "checked_version",
]

FIT_FORMAT_VERSION = "fit/v2"
"""Part of every fit id: bump it when a change to the fit (or to the id's encoding) changes ids."""


def check_finite(what: str, values: Any) -> None:
    """Refuse (ValueError) a result whose ``values`` hold NaN or infinity anywhere."""

    def walk(value):
        if isinstance(value, dict):
            return all(walk(v) for v in value.values())
        if isinstance(value, (list, tuple)):
            return all(walk(v) for v in value)
        if isinstance(value, float):
            return math.isfinite(value)
        return True

    if not walk(values):
        raise ValueError(f"the fit gave non-finite {what}: the data cannot be fitted")


def measured_nk(record: FitRecord) -> SpectralNK | None:
    """
    The measured n, k behind a stored fit: its library material's, or its
    stored data; None for a fit made from curves alone.
    """
    if record.library_material is not None:
        return catalogue_material(record.library_material)
    if record.nk is None:
        return None
    return SpectralNK(
        np.asarray(record.nk["wavelength_nm"]),
        np.asarray(record.nk["n"]),
        np.asarray(record.nk["k"]),
        name=record.name,
        source=record.source,
    )


def nk_view(nk: SpectralNK) -> dict[str, list[float]]:
    """The n, k of a record: ``{"wavelength_nm", "n", "k"}`` as lists."""
    return {"wavelength_nm": nk.wavelength_nm.tolist(), "n": nk.n.tolist(), "k": nk.k.tolist()}


def stored_fit(store: Store, fit_id: str, where: str = "fit_id") -> FitRecord:
    """The record of ``fit_id`` (:func:`with_measured_nk`); ``LookupError`` naming ``where`` when it is not stored."""
    record = store.get_fit(fit_id)
    if record is None:
        raise LookupError(f"`{where}` {fit_id} is not a stored fit")
    return with_measured_nk(store, record)


def nk_holder(record: FitRecord) -> str | None:
    """The id of the record that holds ``record``'s n, k (itself, or the one it refers to)."""
    if record.nk is not None:
        return record.id
    return (record.provenance or {}).get("nk_of")


def nk_record_id(nk: dict[str, list[float]]) -> str:
    """The content address of an n, k record (``{"wavelength_nm", "n", "k"}``)."""
    return content_address("nk record", *(np.asarray(nk[key], dtype=np.float64) for key in ("wavelength_nm", "n", "k")))


def draft_nk_reference(draft: bool, base_record: FitRecord | None, measured: dict | None):
    """
    How a fit keeps the ``measured`` n, k of its base: ``(nk, nk_of, nk_id,
    nk_record)``, the record's own ``nk`` and the references. A saved fit
    keeps its copy; a draft on a stored base refers to the record holding
    it (``nk_of``); a draft on an inline n, k (or on a base that keeps its
    own in an n, k record) refers to the n, k record ``nk_id``, stored once
    (``nk_record``, for :meth:`service.store.Store.put_fit`), content-addressed.
    """
    if not draft or measured is None:
        return measured, None, None, None
    if base_record is not None and base_record.nk_id is None:
        return None, nk_holder(base_record), None, None
    return None, None, nk_record_id(measured), measured


_NK_HOPS = 4  # records followed at most to find an n, k (a draft's base is a draft at most once or twice)


def with_measured_nk(store: Store, record: FitRecord | None) -> FitRecord | None:
    """
    ``record`` with its n, k: a draft stores the id of the record holding
    them (``provenance.nk_of``), or of the n, k record holding them
    (``nk_id``, :meth:`service.store.Store.get_nk`), not a copy; an n, k
    whose holder is gone (an expired draft) stays absent.
    """
    if record is None or record.nk is not None:
        return record
    holder = record
    for _ in range(_NK_HOPS):
        if holder.nk is not None:
            return dataclasses.replace(record, nk=holder.nk)
        if holder.nk_id is not None:
            nk = store.get_nk(holder.nk_id)
            return record if nk is None else dataclasses.replace(record, nk=nk)
        holder_id = (holder.provenance or {}).get("nk_of")
        holder = None if holder_id is None else store.get_fit(holder_id)
        if holder is None:
            return record
    return record


def checked_writable(store: Store) -> None:
    """Raise StoreFull / StoreUnavailable when the store cannot take a save now."""
    reason = store.writable()
    if reason is None:
        return
    if "full" in reason or "free" in reason or "quota" in reason:
        raise StoreFull(f"{reason}; nothing was fitted")
    raise StoreUnavailable(f"{reason}; nothing was fitted")


def checked_version(store: Store, material_id: str, name: str, expected_version: int | None) -> bool:
    """
    Raise StoreConflict (409) when a save naming ``expected_version`` would
    undo a save, a rename or a delete made since
    (:func:`service.store.queries.check_expected`): nothing is fitted for a
    save that would be refused (the save itself checks again, in its
    transaction). Returns whether the material is in the bin now (a save
    without ``expected_version`` takes it out).
    """
    row = store.material(material_id)
    check_expected(row, material_id, name, expected_version, "nothing was fitted")
    return row is not None and row.deleted_at is not None


def fit_record(
    fit_id: str, kind: str, material_id: str, name: str, source: str, job: dict[str, Any], objective: str, **extra: Any
) -> FitRecord:
    """The record of a finished fitting job (material, metrics, timings, convergence)."""
    return FitRecord(
        id=fit_id,
        kind=kind,
        material_id=material_id,
        name=name,
        source=source,
        material=job["material"],
        metrics=job["metrics"],
        timings=job["timings"],
        convergence=job["convergence"],
        objective=objective,
        coverage=job.get("coverage"),
        created_at=time.time(),
        **extra,
    )
