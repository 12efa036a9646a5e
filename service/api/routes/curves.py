"""
Fits from edited RGB curves
===========================

``POST /api/v1/fits/from-curves``: fits the model to RGB curves edited in the
browser and stores the result like any fit (see
:func:`service.fitting_jobs.run_curve_fit`).
"""

from fastapi import APIRouter

router = APIRouter(prefix="/api/v1", tags=["curves"])
