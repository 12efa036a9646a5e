"""
A curve fit's base, as plain data
=================================

:class:`BaseSpec`: what a pool worker needs to build the base a curve fit
edits (a material's n, k, or a fit's model coefficients over its domain),
as picklable plain data; its key is part of the curve fit's id, and its
provenance is kept with the fit (:mod:`service.jobs.curves`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from fitting.fits.curves_base import CurveBase, curve_base_from_coefficients, curve_base_from_nk
from fitting.models.kinds import DEFAULT_MODEL
from fitting.optics.catalogue import catalogue_material
from fitting.optics.nk import SpectralNK

__all__ = ["BaseSpec"]


@dataclass(frozen=True)
class BaseSpec:
    """What a worker needs to build the base: picklable plain data."""

    kind: Literal["nk", "model"]
    name: str
    source: str
    eta_i_range: tuple[float, float]
    library_material: str | None = None
    nk: tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]] | None = None
    coefficients: tuple | None = None
    model: str = DEFAULT_MODEL

    def build(self) -> CurveBase:
        if self.kind == "model":
            return curve_base_from_coefficients(
                np.asarray(self.coefficients), self.eta_i_range, self.name, self.source, self.model
            )
        return curve_base_from_nk(self.spectral_nk(), self.eta_i_range)

    def spectral_nk(self) -> SpectralNK:
        if self.library_material is not None:
            return catalogue_material(self.library_material)
        wavelength, n, k = (np.asarray(a, dtype=np.float64) for a in self.nk)
        return SpectralNK(wavelength, n, k, name=self.name, source=self.source)

    def key(self) -> list:
        return [
            self.kind,
            self.name,
            self.source,
            self.library_material,
            None if self.nk is None else [np.asarray(a) for a in self.nk],
            None if self.coefficients is None else np.asarray(self.coefficients).ravel(),
            list(self.eta_i_range),
            *(() if self.model == DEFAULT_MODEL else (self.model,)),
        ]

    def provenance(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "name": self.name,
            "eta_i_range": list(self.eta_i_range),
            "library_material": self.library_material,
            "coefficients": self.coefficients,
            "model": self.model,
        }
