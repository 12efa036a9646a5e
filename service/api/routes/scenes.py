"""
Scenes
======

``POST /api/v1/scenes``: a pack with only what a scene needs. The body is a
scene description (:mod:`fitting.fits.scene_schema`): the materials a scene uses and, for
each, its coating indices (one eta_i, a set or a range; 1 is uncoated). Each
material is fitted over those eta_i only, with the lowest polynomial degree
that serves it; a saved edited material is shipped as its stored model
(:mod:`service.jobs.scenes`). The answer is the report and the pack, as its
JSON view and as the binary file in base64. It is computed from its input
alone, so it is not stored.
"""

from __future__ import annotations

from fastapi import APIRouter
from fastapi.concurrency import run_in_threadpool

from ...jobs.scenes import prepare_scene, scene_pack
from ...schemas import API_PREFIX, ScenePublic, SceneRequest
from ..deps import FIT_ERROR_RESPONSES, RunnerDep, StoreDep, WriteAccess

router = APIRouter(prefix=API_PREFIX, tags=["scenes"])


@router.post("/scenes", response_model=ScenePublic, responses=FIT_ERROR_RESPONSES, dependencies=[WriteAccess])
async def create_scene_pack(request: SceneRequest, store: StoreDep, runner: RunnerDep) -> ScenePublic:
    """
    Fit each material of the scene over the eta_i it uses, with the lowest
    polynomial degree that serves it (one eta_i: 9 coefficients), and answer
    the pack with, per material, its bytes and Delta E 2000 against the
    general 27-coefficient fit over the same eta_i.
    """
    scene = await run_in_threadpool(prepare_scene, store, request.scene())
    return ScenePublic(**await scene_pack(scene, runner))
