"""
The library to browse
=====================

Responses :class:`LibraryList` (:class:`LibraryEntry` with its
:class:`Swatch`) and :class:`CoatPresets`.
"""

from __future__ import annotations

from pydantic import BaseModel, Field

__all__ = ["Swatch", "LibraryEntry", "LibraryList", "CoatPreset", "CoatPresets"]


class Swatch(BaseModel):
    """The metal's colour under a coat of index `eta_i`, at `angles_deg` in the coat."""

    eta_i: float
    angles_deg: list[float]
    srgb: list[str] = Field(
        description="`#rrggbb` per angle: linear ACEScg to Rec.709 (CAT02), "
        "clipped, sRGB-encoded, exposure 1, no tone mapping"
    )
    acescg: list[list[float]] = Field(
        description="Linear ACEScg reflectance per angle (the 1 nm spectral reference the model is fitted to)"
    )


class LibraryEntry(BaseModel):
    id: str = Field(
        description="The material's id (`GET /materials/{id}`, `POST /fits` `material`): "
        "a library symbol (`Au`) or BOOK.PAGE (`Ti.Johnson`)"
    )
    symbol: str = Field(description="Symbol or formula, e.g. Au, TiN, Cu-Zn")
    name: str = Field(description="Common name, e.g. gold, brass 70/30")
    category: str = Field(description="metal, alloy, nitride, carbide, semiconductor, ...")
    label: str = Field(description="The page's label in the database (authors, year, what was measured)")
    preferred: bool = Field(description='The page a bare name or symbol fits (`"material": "gold"`)')
    source: str = Field(description="The data's citation as the database gives it")
    reference: str = Field(description="The citation alone (authors, title, journal)")
    database: str
    page: str = Field(description="shelf/book/page of the database")
    page_url: str
    wavelength_range_nm: tuple[float, float]
    coverage: float = Field(description="Covered fraction of 360-830 nm")
    swatch: Swatch


class LibraryList(BaseModel):
    eta_i: float
    total: int = Field(description="Conductors matching (before `limit`)")
    materials: list[LibraryEntry]
    suggestions: list[LibraryEntry] = Field(
        default_factory=list,
        description="When `q` matches nothing: what it may have meant (the search less one word, "
        "else the names nearest in spelling), at most 3; else empty",
    )


class CoatPreset(BaseModel):
    id: str
    name: str
    eta_i: float
    source: str


class CoatPresets(BaseModel):
    """Common clear coats by their index at 589 nm (fitting.domain.COAT_PRESETS)."""

    presets: list[CoatPreset]
