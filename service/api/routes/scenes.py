"""
Scenes
======

``POST /api/v1/scenes``: a scene's materials together.
"""

from fastapi import APIRouter

router = APIRouter(prefix="/api/v1", tags=["scenes"])
