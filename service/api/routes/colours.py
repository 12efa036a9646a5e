"""
Curves from colours
===================

-   ``POST /api/v1/colour-curves``: the reflectance curves (linear ACEScg)
    at given coating indices of a metal given by a base colour (F0) and an
    edge tint (F82 tint), seen in air or from under a coat: the inversion of
    ``POST /fits`` with ``f0`` and ``f82`` (:mod:`service.jobs.edge_tint`),
    nothing stored. The editor's colour controls set its edits to them.
"""

from __future__ import annotations

from fastapi import APIRouter
from fastapi.concurrency import run_in_threadpool

from ...jobs.edge_tint import colour_curves
from ...schemas import API_PREFIX, ColourCurves, ColourCurvesRequest
from ..deps import ERROR_RESPONSES

router = APIRouter(prefix=API_PREFIX, tags=["curves"])


@router.post("/colour-curves", response_model=ColourCurves, responses=ERROR_RESPONSES)
async def post_colour_curves(request: ColourCurvesRequest) -> ColourCurves:
    """
    The curves at each `eta_i` of the metal whose F0 and F82 tint are seen
    from a medium of index `seen_at` (1: in air), with its per-channel
    index in air and whether each channel's tint was reachable.
    """
    return ColourCurves(
        **await run_in_threadpool(
            colour_curves, request.f0, request.f82, request.space, request.seen_at, request.eta_i, request.samples
        )
    )
