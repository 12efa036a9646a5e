"""
Versions and edits
==================

-   ``GET /api/v1/materials/{material_id}/versions?limit=&before=``: its
    saves, newest first (each save is a version, 1 the first).
-   ``GET /api/v1/materials/{material_id}/versions/{version}``: the fit of one save.
-   ``GET /api/v1/fits/{fit_id}/edit``: what reopens a fit in the editor
    (its base and edited curves; :func:`service.jobs.materials.fit_edit`).
-   ``POST /api/v1/fits/{fit_id}/link``: the editor's link to a fit; a
    draft is then kept ``COATED_DRAFT_TTL_S`` from now, and the answer
    says until when.
"""

from __future__ import annotations

import time
from typing import Annotated

from fastapi import APIRouter, Path, Query
from fastapi.concurrency import run_in_threadpool

from ...jobs.common import stored_fit, with_measured_nk
from ...jobs.evaluation import ensure_metrics
from ...jobs.materials import fit_edit, share_url
from ...schemas import API_PREFIX, INT64_MAX, FitEdit, FitLink, FitPublic, VersionList, VersionSummary, fit_public
from ..deps import (
    ERROR_RESPONSES,
    FIT_ERROR_RESPONSES,
    NOT_FOUND,
    FitIdPath,
    MaterialIdPath,
    RunnerDep,
    SettingsDep,
    StoreDep,
    WriteAccess,
)

router = APIRouter(prefix=API_PREFIX, tags=["materials"])


@router.get("/materials/{material_id}/versions", response_model=VersionList, responses={**ERROR_RESPONSES, **NOT_FOUND})
def list_versions(
    material_id: MaterialIdPath,
    store: StoreDep,
    limit: Annotated[int, Query(ge=1, le=100, description="Versions per page")] = 50,
    before: Annotated[int | None, Query(ge=1, le=INT64_MAX, description="`next_before` of the previous page")] = None,
) -> VersionList:
    """Every save of a material, newest first: each is a version (1 the first), reachable by its fit id."""
    version = store.material_version(material_id)
    if version == 0:
        raise LookupError(f"`material_id` {material_id!r} has no saves")
    rows = store.material_versions(material_id, before, limit)
    versions = []
    for row in rows:
        record, model = row.record, {}
        if record is not None:
            model = (record.metrics or {}).get("model_float16") or {}
        versions.append(
            VersionSummary(
                version=row.version,
                fit_id=row.fit_id,
                saved_at=row.saved_at,
                name=record.name if record else None,
                kind=record.kind if record else None,
                delta_E_mean=model.get("delta_E_mean"),
                delta_E_max=model.get("delta_E_max"),
                fit_url=f"{API_PREFIX}/fits/{row.fit_id}",
                pack_url=f"{API_PREFIX}/fits/{row.fit_id}/pack",
                share_url=share_url(material_id, row.version),
            )
        )
    next_before = rows[-1].version if len(rows) == limit and rows[-1].version > 1 else None
    return VersionList(material_id=material_id, version=version, versions=versions, next_before=next_before)


@router.get(
    "/materials/{material_id}/versions/{version}",
    response_model=FitPublic,
    responses={**ERROR_RESPONSES, **NOT_FOUND, **FIT_ERROR_RESPONSES},
)
async def get_version(
    material_id: MaterialIdPath,
    store: StoreDep,
    runner: RunnerDep,
    version: Annotated[int, Path(ge=1, le=INT64_MAX, description="1 for the first save")],
) -> FitPublic:
    """The fit saved as one version of a material (download it from its `links`), with its metrics."""
    record = await run_in_threadpool(_version_fit, store, material_id, version)
    return fit_public(await ensure_metrics(record, store, runner))


def _version_fit(store, material_id: str, version: int):
    record = store.version_fit(material_id, version)
    if record is None:
        raise LookupError(
            f"material {material_id!r} has no version {version} (it has {store.material_version(material_id)})"
        )
    return with_measured_nk(store, record)


@router.get("/fits/{fit_id}/edit", response_model=FitEdit, responses={**ERROR_RESPONSES, **NOT_FOUND}, tags=["curves"])
def get_fit_edit(fit_id: FitIdPath, store: StoreDep) -> FitEdit:
    """
    What reopens a stored fit in the editor: its base and its edited curves
    (the request that made it, ready to post again with `expected_version`),
    and the material's name and version now.
    """
    return FitEdit(**fit_edit(store, stored_fit(store, fit_id)))


@router.post(
    "/fits/{fit_id}/link",
    response_model=FitLink,
    responses={**ERROR_RESPONSES, **NOT_FOUND},
    tags=["curves"],
    dependencies=[WriteAccess],
)
def link_fit(fit_id: FitIdPath, store: StoreDep, settings: SettingsDep) -> FitLink:
    """
    The editor's link to a stored fit. A draft (an unsaved edit) is kept
    `draft_ttl_s` (`GET /domain`) from now, whatever its age, and removed
    then unless saved; `expires_at` says when. Past the drafts' quota the
    drafts no link keeps go first.
    """
    expires_at = store.keep_draft(fit_id, time.time() + settings.draft_ttl_s)
    return FitLink(fit_id=fit_id, url=f"/?fit={fit_id}", draft=expires_at is not None, expires_at=expires_at)
