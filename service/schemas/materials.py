"""
Materials
=========

Responses :class:`MaterialSummary`, :class:`MaterialList` (one page, with
the cursor of the next), :class:`MaterialDetail`.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field

from ..store import FIT_KINDS
from .fits import FitPublic

__all__ = ["MaterialSummary", "MaterialList", "MaterialDetail"]


class MaterialSummary(BaseModel):
    id: str
    name: str
    kind: Literal[FIT_KINDS]  # type: ignore[valid-type]
    source: str
    coverage: float | None = None
    latest_fit_id: str | None = None
    version: int = Field(0, description="Saves of the material so far (0: never saved); a save of "
                                        "edited curves may name it as `expected_version` (409 when "
                                        "another save came first)")


class MaterialList(BaseModel):
    """One page: the built-in library first (on the first page), then saved materials, oldest first."""

    materials: list[MaterialSummary]
    next_cursor: int | None = Field(None, description="Pass as `cursor` for the next page; null at the end")
    skipped: list[str] = Field(default_factory=list,
                               description="Saved materials whose summary could not be read (logged)")


class MaterialDetail(MaterialSummary):
    wavelength_range_nm: tuple[float, float] | None = None
    latest_fit: FitPublic | None = None
