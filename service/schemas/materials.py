"""
Materials
=========

Responses :class:`MaterialSummary`, :class:`MaterialList` (one page, with
the cursor of the next), :class:`MaterialDetail`, :class:`VersionList` (a
material's saves), :class:`FitEdit` (what reopens a fit in the editor);
the request :class:`MaterialRename`.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from ..store import FIT_KINDS, MaterialRow
from .common import MaterialName, RequestModel
from .fits import FitPublic

__all__ = [
    "MaterialSummary",
    "material_summary",
    "MaterialList",
    "MaterialDetail",
    "MaterialRename",
    "VersionSummary",
    "VersionList",
    "FitEdit",
    "FitLink",
    "LISTING_KINDS",
]

LISTING_KINDS = ("library", "curves", "nk")
"""What ``GET /materials?kind=`` selects: built-in, saved edits (the artist's), n, k uploads."""


class MaterialSummary(BaseModel):
    id: str
    name: str
    kind: Literal[FIT_KINDS]  # type: ignore[valid-type]
    source: str
    coverage: float | None = None
    latest_fit_id: str | None = None
    version: int = Field(
        0,
        description="Saves of the material so far (0: never saved); a save of "
        "edited curves may name it as `expected_version` (409 when "
        "another save came first)",
    )
    deleted_at: float | None = Field(
        None, description="Unix time it went to the bin (`DELETE /materials/{id}`); null: not deleted"
    )
    share_url: str = Field(description="The editor's link that reopens it: `/?material={id}`")


def material_summary(row: MaterialRow, share_url: str) -> MaterialSummary:
    """A material's summary row as the API answers it, with its link ``share_url``."""
    return MaterialSummary(
        id=row.material_id,
        name=row.name,
        kind=row.kind,
        source=row.source,
        coverage=row.coverage,
        latest_fit_id=row.latest_fit_id,
        version=row.version,
        deleted_at=row.deleted_at,
        share_url=share_url,
    )


class MaterialList(BaseModel):
    """One page: the built-in library first (on the first page), then saved materials, oldest first."""

    materials: list[MaterialSummary]
    next_cursor: int | None = Field(None, description="Pass as `cursor` for the next page; null at the end")
    skipped: list[str] = Field(
        default_factory=list, description="Saved materials whose summary could not be read (logged)"
    )


class MaterialDetail(MaterialSummary):
    wavelength_range_nm: tuple[float, float] | None = None
    latest_fit: FitPublic | None = None


class MaterialRename(RequestModel):
    """A new name for a saved material (not a save: its version and fits stay as they are)."""

    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{"name": "warm brass"}]})

    name: MaterialName


class VersionSummary(BaseModel):
    """One save of a material: open it with `GET /fits/{fit_id}`, download it from `links.pack`."""

    version: int = Field(description="1 for the first save; the material's `version` is its latest")
    fit_id: str
    saved_at: float
    name: str | None = Field(None, description="The name it was saved under (null: record unreadable)")
    kind: Literal[FIT_KINDS] | None = None  # type: ignore[valid-type]
    delta_E_mean: float | None = Field(None, description="`metrics.model.delta_E_mean` of the fit")
    delta_E_max: float | None = None
    fit_url: str
    pack_url: str
    share_url: str = Field(description="The editor's link to this version: `/?material={id}&version={n}`")


class VersionList(BaseModel):
    """A material's saves, newest first."""

    material_id: str
    version: int = Field(description="The material's latest version (its number of saves)")
    versions: list[VersionSummary]
    next_before: int | None = Field(None, description="Pass as `before` for older saves; null at the first")


class FitEdit(BaseModel):
    """
    What reopens a stored fit in the editor. For a curve fit, ``request``
    is the ``POST /fits/from-curves`` body that made it (its ``base`` and
    edited ``curves``; ``name`` and ``material_id`` the material's now):
    load the base, apply the curves, and save again with the same
    ``material_id`` and ``expected_version``. A library or n, k fit has no
    edit: ``base`` is what to open (``{"material"}`` or ``{"fit"}``).
    """

    fit_id: str
    kind: Literal[FIT_KINDS]  # type: ignore[valid-type]
    material_id: str
    name: str
    base: dict[str, Any] | None = Field(
        None,
        description='`{"material": name}`, `{"fit": id}` or `{"nk": {...}}`: what the edit starts '
        "from (null: curves alone)",
    )
    request: dict[str, Any] | None = Field(
        None, description="The curve fit's request, ready to post again (null for library and n, k fits)"
    )
    version: int = Field(0, description="The material's version now (send it as `expected_version`)")


class FitLink(BaseModel):
    """A link that reopens a fit in the editor, and how long it works."""

    fit_id: str
    url: str = Field(description="The editor's link (`/?fit={fit_id}`), relative to the service")
    draft: bool = Field(description="Whether it opens an unsaved edit (a draft), kept until `expires_at`")
    expires_at: float | None = Field(
        description="Unix time the draft is removed (null: a saved fit, or the base of one, never is)"
    )
