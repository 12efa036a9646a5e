"""
The library to browse
=====================

-   ``GET /api/v1/library?q=&eta_i=&limit=``: the catalogue's conductors with
    common names, symbols, categories, sources, ranges and swatches at
    ``eta_i`` (:mod:`service.jobs.library`); ``q`` keeps those whose name,
    symbol, category or page description holds every word of it, name and
    symbol matches first (never the citation); a ``q`` that matches nothing
    is answered with ``suggestions``, what it may have meant.
-   ``GET /api/v1/coat-presets``: common clear coats and their eta_i, with sources.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query
from fastapi.concurrency import run_in_threadpool

from fitting.optics.catalogue import search_catalogue

from ...jobs.library import coat_presets, library_entries, library_suggestions
from ...schemas import API_PREFIX, ETA_I_LIMITS, CoatPresets, LibraryList
from ..deps import ERROR_RESPONSES

router = APIRouter(prefix=API_PREFIX, tags=["library"])


@router.get("/library", response_model=LibraryList, responses=ERROR_RESPONSES)
async def get_library(
    eta_i: Annotated[
        float,
        Query(ge=ETA_I_LIMITS[0], le=ETA_I_LIMITS[1], allow_inf_nan=False, description="Coating index of the swatches"),
    ] = 1.5,
    q: Annotated[
        str | None,
        Query(
            min_length=1,
            max_length=200,
            description="Words each in the name, symbol, category or page "
            "description (case-insensitive); best matches first",
        ),
    ] = None,
    limit: Annotated[int | None, Query(ge=1, le=1000, description="At most this many (default all)")] = None,
) -> LibraryList:
    """The library's conductors: names, symbols, sources, ranges, swatches under the coat at `eta_i`."""
    found = await run_in_threadpool(library_entries, eta_i, q, limit)
    suggested = await run_in_threadpool(library_suggestions, eta_i, q) if q and not found else []
    return LibraryList(eta_i=eta_i, total=len(search_catalogue(q)), materials=found, suggestions=suggested)


@router.get("/coat-presets", response_model=CoatPresets, responses=ERROR_RESPONSES)
def get_coat_presets() -> CoatPresets:
    """Common clear coats (air, water, lacquer, glass, ...) by their index at 589 nm, with sources."""
    return CoatPresets(presets=coat_presets())
