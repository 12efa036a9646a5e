"""
The library to browse
=====================

:func:`library_entries`: per conductor of the catalogue
(:mod:`fitting.optics.catalogue`: every opaque page a batch fits) its
common name, symbol, category, data source (citation, refractiveindex.info
page), wavelength range, visible coverage and a swatch: the colour of the
metal under a coat of index ``eta_i`` at a few angles, for the editor's
library list and its search (name and symbol matches first, never inside
the citation: :func:`fitting.optics.catalogue.search_catalogue`).

The swatch is the exact spectral reference the model is fitted to
(:func:`fitting.colour.reference.reference_ACEScg`, 1 nm), which the
float16 model follows within its Delta E (docs/results.md), converted as
the preview displays reflectance: linear ACEScg to linear Rec.709 (CAT02,
white to white), clipped to [0, 1], sRGB-encoded (IEC 61966-2-1), at
exposure 1 with no tone mapping. The coat's own surface reflection is not
part of it (the colour *under* the coat).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from fitting.colour.colorimetry import colour_science
from fitting.colour.reference import reference_ACEScg
from fitting.domain import COAT_PRESETS, check_eta_i, cos_theta_from_angle
from fitting.exports.colour_space import ACEScg_to_lin_rec709
from fitting.optics.catalogue import catalogue, catalogue_material, search_catalogue, suggest_materials

__all__ = ["SWATCH_ANGLES_DEG", "library_entries", "library_suggestions", "library_about", "srgb_hex", "coat_presets"]

SWATCH_ANGLES_DEG: tuple[float, ...] = (0.0, 45.0, 70.0, 85.0)
"""The angles in the coating of a swatch: normal incidence, then towards grazing."""


def srgb_hex(ACEScg) -> list[str]:
    """``#rrggbb`` of linear ACEScg rows as displayed: Rec.709 (CAT02), clipped, sRGB-encoded."""
    linear = np.clip(ACEScg_to_lin_rec709(np.atleast_2d(ACEScg)), 0.0, 1.0)
    encoded = np.round(colour_science().cctf_encoding(linear, function="sRGB") * 255.0).astype(int)
    return ["#" + "".join(f"{v:02x}" for v in row) for row in encoded]


@functools.lru_cache(maxsize=2048)
def _swatch(material_id: str, eta_i: float) -> tuple[tuple[tuple[float, ...], ...], tuple[str, ...]]:
    mu = cos_theta_from_angle(np.asarray(SWATCH_ANGLES_DEG))
    rgb = reference_ACEScg(catalogue_material(material_id), mu, eta_i)
    return tuple(tuple(float(v) for v in row) for row in rgb), tuple(srgb_hex(rgb))


def _page_url(page: str) -> str:
    shelf, book, name = page.split("/", 2)
    return f"https://refractiveindex.info/?shelf={shelf}&book={book}&page={name}"


def library_about(material_id: str) -> dict[str, Any]:
    """
    A catalogue conductor as the API shows it: id, common name, symbol,
    category, page, label, citation, range, coverage (KeyError for an unknown id).
    """
    entry = catalogue()[material_id]
    source = f"refractiveindex.info {entry['page']}" + (f": {entry['reference']}" if entry["reference"] else "")
    return {
        "id": entry["id"],
        "symbol": entry["symbol"],
        "name": entry["name"],
        "category": entry["category"],
        "label": entry["label"],
        "preferred": entry["preferred"],
        "source": source,
        "reference": entry["reference"],
        "database": "refractiveindex.info",
        "page": entry["page"],
        "page_url": _page_url(entry["page"]),
        "wavelength_range_nm": tuple(entry["wavelength_range_nm"]),
        "coverage": entry["coverage"],
    }


def library_entries(eta_i: float, query: str | None = None, limit: int | None = None) -> list[dict[str, Any]]:
    """The catalogue's conductors (those matching ``query``, best first, when given; at most
    ``limit``), each with its swatch at ``eta_i``."""
    eta_i = check_eta_i(eta_i)
    return [_listed(entry, eta_i) for entry in search_catalogue(query)[:limit]]


def library_suggestions(eta_i: float, query: str) -> list[dict[str, Any]]:
    """What ``query``, which matches nothing, may have meant
    (:func:`fitting.optics.catalogue.suggest_materials`), listed as :func:`library_entries` lists."""
    eta_i = check_eta_i(eta_i)
    return [_listed(entry, eta_i) for entry in suggest_materials(query)]


def _listed(entry: dict[str, Any], eta_i: float) -> dict[str, Any]:
    acescg, hexes = _swatch(entry["id"], eta_i)
    return {
        **library_about(entry["id"]),
        "swatch": {
            "eta_i": eta_i,
            "angles_deg": list(SWATCH_ANGLES_DEG),
            "srgb": list(hexes),
            "acescg": [list(row) for row in acescg],
        },
    }


def coat_presets() -> list[dict[str, Any]]:
    """:data:`fitting.domain.COAT_PRESETS` as JSON rows."""
    return [{"id": key, "name": name, "eta_i": eta_i, "source": source} for key, name, eta_i, source in COAT_PRESETS]
