"""
Materials
=========

``GET /api/v1/materials?limit=&cursor=``: one page of materials: the
built-in library (first page only), then saved materials (fits of uploaded
or inline n, k and of edited curves), oldest first, read from the store's
summary rows, so a page costs what it returns. ``next_cursor`` continues.
``GET /api/v1/materials/{material_id}``: one material with its latest fit.
"""

from __future__ import annotations

import functools
from typing import Annotated

from fastapi import APIRouter, Path, Query

from fitting.optics.library import LIBRARY_NAMES, library_material
from fitting.optics.nk import visible_coverage

from ...schemas import API_PREFIX, INT64_MAX, MATERIAL_ID_PATTERN, MaterialDetail, MaterialList, MaterialSummary, fit_public
from ...jobs.common import with_measured_nk
from ..deps import ERROR_RESPONSES, NOT_FOUND, SettingsDep, StoreDep

router = APIRouter(prefix=f"{API_PREFIX}/materials", tags=["materials"])


@functools.cache
def _library_entry(name: str) -> tuple[str, float, tuple[float, float]]:
    nk = library_material(name)
    return nk.source, visible_coverage(nk.wavelength_range_nm), nk.wavelength_range_nm


@router.get("", response_model=MaterialList, responses=ERROR_RESPONSES)
def list_materials(
    store: StoreDep, settings: SettingsDep,
    limit: Annotated[int | None, Query(ge=1, le=INT64_MAX, description="Saved materials per page "
                                       "(default and most: COATED_MATERIALS_PAGE_MAX)")] = None,
    cursor: Annotated[int | None, Query(ge=0, le=INT64_MAX,
                                        description="`next_cursor` of the previous page")] = None,
) -> MaterialList:
    """The 22 built-in conductors (first page), then the saved materials, oldest first."""
    limit = min(limit or settings.materials_page_max, settings.materials_page_max)
    materials = []
    if cursor is None:
        latest = store.latest_fit_ids(list(LIBRARY_NAMES))
        for name in LIBRARY_NAMES:
            source, coverage, _ = _library_entry(name)
            materials.append(MaterialSummary(id=name, name=name, kind="library", source=source,
                                             coverage=coverage, latest_fit_id=latest.get(name)))
    page = store.material_page(cursor, limit)
    for row in page.rows:
        materials.append(MaterialSummary(
            id=row.material_id, name=row.name, kind=row.kind, source=row.source,
            coverage=row.coverage, latest_fit_id=row.latest_fit_id, version=row.version,
        ))
    return MaterialList(materials=materials, next_cursor=page.next_cursor, skipped=page.skipped)


@router.get("/{material_id}", response_model=MaterialDetail, responses={**ERROR_RESPONSES, **NOT_FOUND})
def get_material(
    material_id: Annotated[str, Path(pattern=MATERIAL_ID_PATTERN,
                                     description="A library name or a saved material's id")],
    store: StoreDep,
) -> MaterialDetail:
    """One material with its latest fit (None for a library material not fitted yet)."""
    latest = with_measured_nk(store, store.latest_fit(material_id))
    version = store.material_version(material_id)
    if material_id in LIBRARY_NAMES:
        source, coverage, wavelength_range = _library_entry(material_id)
        return MaterialDetail(
            id=material_id, name=material_id, kind="library", source=source,
            coverage=coverage, latest_fit_id=latest.id if latest else None, version=version,
            wavelength_range_nm=wavelength_range,
            latest_fit=fit_public(latest) if latest else None,
        )
    if latest is None:
        raise LookupError(f"`material_id` {material_id!r} is neither a built-in material nor a saved one")
    wavelength_range = None
    if latest.nk is not None:
        wavelength_range = (latest.nk["wavelength_nm"][0], latest.nk["wavelength_nm"][-1])
    return MaterialDetail(
        id=material_id, name=latest.name, kind=latest.kind, source=latest.source,
        coverage=latest.coverage, latest_fit_id=latest.id, version=version,
        wavelength_range_nm=wavelength_range, latest_fit=fit_public(latest),
    )
