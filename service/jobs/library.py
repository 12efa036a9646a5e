"""
The library to browse
=====================

:func:`library_entries`: per built-in material its symbol, full name, data
source (citation, refractiveindex.info page), wavelength range, visible
coverage and a swatch: the colour of the metal under a coat of index
``eta_i`` at a few angles, for the editor's library list and its search
(:func:`matches`: by symbol, name or source).

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
from fitting.optics.library import FULL_NAMES, LIBRARY, LIBRARY_NAMES, library_material, page_url
from fitting.optics.nk import visible_coverage

__all__ = ["SWATCH_ANGLES_DEG", "library_entries", "matches", "srgb_hex", "coat_presets"]

SWATCH_ANGLES_DEG: tuple[float, ...] = (0.0, 45.0, 70.0, 85.0)
"""The angles in the coating of a swatch: normal incidence, then towards grazing."""


def srgb_hex(ACEScg) -> list[str]:
    """``#rrggbb`` of linear ACEScg rows as displayed: Rec.709 (CAT02), clipped, sRGB-encoded."""
    linear = np.clip(ACEScg_to_lin_rec709(np.atleast_2d(ACEScg)), 0.0, 1.0)
    encoded = np.round(colour_science().cctf_encoding(linear, function="sRGB") * 255.0).astype(int)
    return ["#" + "".join(f"{v:02x}" for v in row) for row in encoded]


@functools.lru_cache(maxsize=64)
def _swatch(name: str, eta_i: float) -> tuple[tuple[tuple[float, ...], ...], tuple[str, ...]]:
    mu = cos_theta_from_angle(np.asarray(SWATCH_ANGLES_DEG))
    rgb = reference_ACEScg(library_material(name), mu, eta_i)
    return tuple(tuple(float(v) for v in row) for row in rgb), tuple(srgb_hex(rgb))


@functools.cache
def _about(name: str) -> dict[str, Any]:
    nk = library_material(name)
    shelf, book, page = LIBRARY[name]
    citation = nk.source.split(": ", 1)[1] if ": " in nk.source else nk.source
    return {
        "id": name, "symbol": name, "name": FULL_NAMES[name],
        "source": nk.source, "reference": " ".join(citation.split()),
        "database": "refractiveindex.info", "page": f"{shelf}/{book}/{page}", "page_url": page_url(name),
        "wavelength_range_nm": tuple(float(v) for v in nk.wavelength_range_nm),
        "coverage": float(visible_coverage(nk.wavelength_range_nm)),
    }


def matches(entry: dict[str, Any], query: str) -> bool:
    """Whether ``query`` (case-insensitive, every word) is in the symbol, name, source or page."""
    text = " ".join((entry["symbol"], entry["name"], entry["source"], entry["page"])).casefold()
    return all(word in text for word in query.casefold().split())


def library_entries(eta_i: float, query: str | None = None) -> list[dict[str, Any]]:
    """The library materials (those matching ``query`` when given), each with its swatch at ``eta_i``."""
    eta_i = check_eta_i(eta_i)
    out = []
    for name in LIBRARY_NAMES:
        entry = _about(name)
        if query and not matches(entry, query):
            continue
        acescg, hexes = _swatch(name, eta_i)
        out.append({**entry, "swatch": {"eta_i": eta_i, "angles_deg": list(SWATCH_ANGLES_DEG),
                                        "srgb": list(hexes), "acescg": [list(row) for row in acescg]}})
    return out


def coat_presets() -> list[dict[str, Any]]:
    """:data:`fitting.domain.COAT_PRESETS` as JSON rows."""
    return [{"id": key, "name": name, "eta_i": eta_i, "source": source}
            for key, name, eta_i, source in COAT_PRESETS]
