"""
Imports: a file back to its fit
===============================

``POST /api/v1/fits/import``: a binary pack, its JSON view, or an export of
this service (glTF or GLB, MaterialX, OpenPBR, Blender script) read and
checked by :func:`fitting.exports.readback.read_fit_file` (checksum,
version, values), then:

-   the file names a stored fit (an export's ``fit_id``, a JSON view's
    ``metrics.fit_id``) whose float16 model is the file's, bit for bit: that
    fit, as stored (200);
-   else a new record of the model (201), kind ``curves`` (a fit defined by
    its model, exported from its model curve), id a content address of the
    model's binary pack, saved as its own material, its provenance naming
    the file's format and identity; imported again, the same record (200).

A file that names a stored fit with another model is refused (422): the
id and the coefficients disagree.

-   :func:`import_fit`: the record and whether it is new.
"""

from __future__ import annotations

import asyncio

from fitting.exports.readback import read_fit_file
from fitting.models.pack import encode_pack, material_from_json, material_to_json

from ..store import FitRecord, Store
from .common import FIT_FORMAT_VERSION, checked_writable, content_address, fit_record

__all__ = ["import_fit"]

IMPORT_FORMAT = "import/v1"
"""Part of an imported fit's id."""


def _read(data: bytes):
    read = read_fit_file(data)
    if len(read.materials) != 1:
        raise ValueError(f"`file` must hold one material to import, got {len(read.materials)}")
    fit_ids = read.identity.get("fit_ids") or [read.identity.get("fit_id")]
    return read, read.materials[0], fit_ids[0]


def _find_or_make(store: Store, read, model, named: str | None) -> tuple[FitRecord, bool]:
    if named is not None:
        stored = store.get_fit(named)
        if stored is not None:
            if material_from_json(stored.material) != model:
                raise ValueError(
                    f"`file` names the stored fit {named}, but its coefficients are not that fit's: "
                    "the file was changed after it was made"
                )
            return stored, False
    pack = encode_pack([model])
    fit_id = content_address(IMPORT_FORMAT, FIT_FORMAT_VERSION, pack)
    stored = store.get_fit(fit_id)
    if stored is not None:
        return stored, False
    checked_writable(store)
    job = {"material": material_to_json(model), "metrics": {}, "timings": {}, "convergence": {}}
    record = fit_record(
        fit_id,
        "curves",
        fit_id,
        model.name,
        model.source,
        job,
        objective="",
        provenance={"imported": {"format": read.format, "identity": read.identity, "named_fit_id": named}},
    )
    return store.put_fit(record), True


async def import_fit(store: Store, data: bytes) -> tuple[FitRecord, bool]:
    """
    The fit a file holds: the stored record it names, or a new one (see the
    module docstring), and whether it was made now.

    Raises
    ------
    ValueError
        For a file that cannot be read or checked (the message names what
        is wrong), or one whose fit id and coefficients disagree.
    """
    read, model, named = await asyncio.to_thread(_read, data)
    return await asyncio.to_thread(_find_or_make, store, read, model, named)
