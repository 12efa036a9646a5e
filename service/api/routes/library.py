"""
The library to browse
=====================

-   ``GET /api/v1/library?q=&eta_i=``: the built-in materials with full
    names, sources, ranges and swatches at ``eta_i`` (:mod:`service.jobs.library`);
    ``q`` keeps those whose symbol, name or source holds every word of it.
-   ``GET /api/v1/coat-presets``: common clear coats and their eta_i, with sources.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query
from fastapi.concurrency import run_in_threadpool

from ...jobs.library import coat_presets, library_entries
from ...schemas import API_PREFIX, ETA_I_LIMITS, CoatPresets, LibraryList
from ..deps import ERROR_RESPONSES

router = APIRouter(prefix=API_PREFIX, tags=["library"])


@router.get("/library", response_model=LibraryList, responses=ERROR_RESPONSES)
async def get_library(
    eta_i: Annotated[float, Query(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False,
                                  description="Coating index of the swatches")] = 1.5,
    q: Annotated[str | None, Query(min_length=1, max_length=200,
                                   description="Words each in the symbol, name or source "
                                               "(case-insensitive)")] = None,
) -> LibraryList:
    """The built-in conductors to browse: names, sources, ranges, swatches under the coat at `eta_i`."""
    return LibraryList(eta_i=eta_i, materials=await run_in_threadpool(library_entries, eta_i, q))


@router.get("/coat-presets", response_model=CoatPresets, responses=ERROR_RESPONSES)
def get_coat_presets() -> CoatPresets:
    """Common clear coats (air, water, lacquer, glass, ...) by their index at 589 nm, with sources."""
    return CoatPresets(presets=coat_presets())
