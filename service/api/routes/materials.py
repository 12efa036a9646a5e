"""
Materials
=========

-   ``GET /api/v1/materials?kind=&q=&deleted=&limit=&cursor=``: one page of
    materials: the library (first page only: each conductor's preferred
    page, or with ``q`` every catalogue page matching it), then saved
    materials, oldest first, read from the store's summary rows, so a page
    costs what it returns. ``kind`` selects: ``library``, ``curves`` (the
    artist's saved edits) and ``nk`` (fits of uploaded or inline n, k, kept
    apart: listed only when asked); default ``library`` and ``curves``.
    ``q`` keeps those whose name, symbol or source holds it; ``deleted``
    lists the bin instead. ``next_cursor`` continues.
-   ``GET /api/v1/materials/{material_id}``: one material with its latest fit.

Renames and the bin: :mod:`service.api.routes.material_edits`; a material's
versions and a fit's edit: :mod:`service.api.routes.versions`.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query

from fitting.optics.catalogue import catalogue, search_catalogue

from ...jobs.common import with_measured_nk
from ...jobs.library import library_about
from ...jobs.materials import share_url as _share
from ...schemas import (
    API_PREFIX,
    INT64_MAX,
    LISTING_KINDS,
    ErrorBody,
    MaterialDetail,
    MaterialList,
    MaterialSummary,
    fit_public,
    material_summary,
)
from ...store import MaterialRow
from ..deps import ERROR_RESPONSES, FIT_ERROR_RESPONSES, NOT_FOUND, MaterialIdPath, SettingsDep, StoreDep

router = APIRouter(prefix=API_PREFIX, tags=["materials"])

WRITE_RESPONSES = {
    **FIT_ERROR_RESPONSES,
    **NOT_FOUND,
    409: {"model": ErrorBody, "description": "Another saved edited material is called `name`"},
}


def _summary(row: MaterialRow) -> MaterialSummary:
    return material_summary(row, _share(row.material_id))


@router.get("/materials", response_model=MaterialList, responses=ERROR_RESPONSES)
def list_materials(
    store: StoreDep,
    settings: SettingsDep,
    limit: Annotated[
        int | None,
        Query(ge=1, le=INT64_MAX, description="Saved materials per page (default and most: COATED_MATERIALS_PAGE_MAX)"),
    ] = None,
    cursor: Annotated[int | None, Query(ge=0, le=INT64_MAX, description="`next_cursor` of the previous page")] = None,
    kind: Annotated[
        list[str] | None,
        Query(
            description="library | curves (saved edits) | nk (n, k uploads); repeat for several; "
            "default library and curves"
        ),
    ] = None,
    q: Annotated[
        str | None,
        Query(min_length=1, max_length=200, description="Only names, symbols or sources holding it (case-insensitive)"),
    ] = None,
    deleted: Annotated[bool, Query(description="List the bin (deleted materials) instead")] = False,
) -> MaterialList:
    """The library's conductors (first page), then the saved materials of `kind`, oldest first."""
    kinds = tuple(dict.fromkeys(kind or ("library", "curves")))
    unknown = [k for k in kinds if k not in LISTING_KINDS]
    if unknown:
        raise ValueError(f"`kind` must be one of {', '.join(LISTING_KINDS)}, got {unknown[0][:40]!r}")
    limit = min(limit or settings.materials_page_max, settings.materials_page_max)
    materials = []
    if cursor is None and "library" in kinds and not deleted:
        listed = [e["id"] for e in search_catalogue(q) if q or e["preferred"]]
        latest = store.latest_fit_ids(listed)
        for material_id in listed:
            about = library_about(material_id)
            materials.append(
                MaterialSummary(
                    id=material_id,
                    name=f"{about['name']} ({about['symbol']})",
                    kind="library",
                    source=about["source"],
                    coverage=about["coverage"],
                    latest_fit_id=latest.get(material_id),
                    share_url=_share(material_id),
                )
            )
    saved_kinds = tuple(k for k in kinds if k != "library")
    if not saved_kinds:
        return MaterialList(materials=materials)
    page = store.material_page(cursor, limit, saved_kinds, deleted, q)
    materials += [_summary(row) for row in page.rows]
    return MaterialList(materials=materials, next_cursor=page.next_cursor, skipped=page.skipped)


@router.get("/materials/{material_id}", response_model=MaterialDetail, responses={**ERROR_RESPONSES, **NOT_FOUND})
def get_material(material_id: MaterialIdPath, store: StoreDep) -> MaterialDetail:
    """One material with its latest fit (None for a library material not fitted yet); one in the bin too."""
    latest = with_measured_nk(store, store.latest_fit(material_id))
    if material_id in catalogue():
        about = library_about(material_id)
        return MaterialDetail(
            id=material_id,
            name=f"{about['name']} ({about['symbol']})",
            kind="library",
            source=about["source"],
            coverage=about["coverage"],
            latest_fit_id=latest.id if latest else None,
            version=store.material_version(material_id),
            share_url=_share(material_id),
            wavelength_range_nm=about["wavelength_range_nm"],
            latest_fit=fit_public(latest) if latest else None,
        )
    row = store.material(material_id)
    if latest is None or row is None:
        raise LookupError(f"`material_id` {material_id!r} is neither a built-in material nor a saved one")
    wavelength_range = None
    if latest.nk is not None:
        wavelength_range = (latest.nk["wavelength_nm"][0], latest.nk["wavelength_nm"][-1])
    return MaterialDetail(**dict(_summary(row)), wavelength_range_nm=wavelength_range, latest_fit=fit_public(latest))
