"""
Material edits
==============

-   ``PATCH /api/v1/materials/{material_id}``: rename (``{"name"}``).
-   ``DELETE /api/v1/materials/{material_id}``: to the bin (soft delete).
-   ``POST /api/v1/materials/{material_id}/restore``: out of the bin.

Listing and reading materials: :mod:`service.api.routes.materials`. The
writes need what saves need (:data:`service.api.deps.WriteAccess`: same
site, and the bearer token when the service requires one).
"""

from __future__ import annotations

from fastapi import APIRouter

from ...jobs.materials import share_url
from ...schemas import API_PREFIX, ErrorBody, MaterialRename, MaterialSummary, material_summary
from ...store import MaterialRow
from ..deps import FIT_ERROR_RESPONSES, NOT_FOUND, MaterialIdPath, StoreDep, WriteAccess

router = APIRouter(prefix=API_PREFIX, tags=["materials"])

WRITE_RESPONSES = {
    **FIT_ERROR_RESPONSES,
    **NOT_FOUND,
    409: {"model": ErrorBody, "description": "Another saved edited material is called `name`"},
}


def _summary(row: MaterialRow) -> MaterialSummary:
    return material_summary(row, share_url(row.material_id))


@router.patch(
    "/materials/{material_id}", response_model=MaterialSummary, responses=WRITE_RESPONSES, dependencies=[WriteAccess]
)
def rename_material(material_id: MaterialIdPath, body: MaterialRename, store: StoreDep) -> MaterialSummary:
    """
    Rename a saved material. Not a save: its version, fits and history stay
    as they are; the next save of it (with its `material_id`) keeps the
    new name, and a save expecting a version read before the rename (still
    carrying the old name) is refused (409 naming the new one). An edited
    material's name is unique among edited materials (409 when another, in
    the bin or not, is called that).
    """
    return _summary(store.rename_material(material_id, body.name.strip()))


@router.delete(
    "/materials/{material_id}", response_model=MaterialSummary, responses=WRITE_RESPONSES, dependencies=[WriteAccess]
)
def delete_material(material_id: MaterialIdPath, store: StoreDep) -> MaterialSummary:
    """
    Move a saved material to the bin: it leaves the listings (`?deleted=true`
    lists the bin), nothing is erased (its fits, downloads and versions stay
    reachable by id), `POST .../restore` brings it back, and so does a save
    of it without `expected_version` (its answer says `restored_from_bin`);
    a save with `expected_version` is refused (409: it would undo the
    delete unseen). Deleting one in the bin again answers the same.
    """
    return _summary(store.delete_material(material_id))


@router.post(
    "/materials/{material_id}/restore",
    response_model=MaterialSummary,
    responses=WRITE_RESPONSES,
    dependencies=[WriteAccess],
)
def restore_material(material_id: MaterialIdPath, store: StoreDep) -> MaterialSummary:
    """Take a material out of the bin (a material not in it answers as it is)."""
    return _summary(store.restore_material(material_id))
