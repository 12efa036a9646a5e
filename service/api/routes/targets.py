"""
Fit targets
===========

What a stored fit was fitted to, at given (cos theta, eta_i): for a curve
fit the blended edited target (with a base) or its curves (without), else
the spectral reference of its n, k. Shared by ``GET /fits/{id}/curves``
(its ``target``) and ``GET /fits/{id}/error-map``.
"""

from __future__ import annotations

import numpy as np

from fitting.fits.curves import CurveFitSettings
from fitting.fits.curves_base import curve_base_from_coefficients, curve_base_from_nk, edited_target
from fitting.fits.curves_input import check_curves
from fitting.models.pack import material_from_json
from fitting.optics.nk import SpectralNK

from ...fitting_jobs import measured_nk
from ...store import FitRecord

__all__ = ["target_at"]

_DEFAULTS = CurveFitSettings()


def _target_of(record: FitRecord, mu: np.ndarray, eta: np.ndarray):
    """(eta_i rows, target (E, M, 3), against) for a stored fit."""
    packed = material_from_json(record.material)
    domain = packed.eta_i_range
    provenance = record.provenance or {}
    if record.kind == "curves":
        request = provenance.get("request", {})
        curves = check_curves(request.get("curves", []))
        base = provenance.get("base")
        if base is None:
            rows = np.array(sorted(c.eta_i for c in curves))
            target = np.stack([next(c for c in curves if c.eta_i == e).sampled(mu) for e in rows])
            return rows, target, "curves"
        if base["kind"] == "model":
            grid = curve_base_from_coefficients(np.asarray(base["coefficients"]), domain, base["name"])
        else:
            grid = curve_base_from_nk(_measured_nk_or_refuse(record), domain)
        E, M = np.meshgrid(eta, mu, indexing="ij")
        width = request.get("blend_width", _DEFAULTS.blend_width)
        return eta, edited_target(grid, curves, M, E, width), "edited target"
    grid = curve_base_from_nk(_measured_nk_or_refuse(record), domain)
    E, M = np.meshgrid(eta, mu, indexing="ij")
    return eta, grid.rgb(M, E), "reference"


def target_at(record: FitRecord, mu: np.ndarray, eta_i: float) -> list[list[float]]:
    """
    A curve fit's target at one eta_i: the blended edited target (with a
    base), or the curve at that eta_i (without; ValueError if none is there).
    """
    rows, target, against = _target_of(record, mu, np.array([float(eta_i)]))
    if against == "curves":
        matches = np.flatnonzero(np.abs(rows - eta_i) < 1e-6)
        if not matches.size:
            raise ValueError(f"fit {record.id} has no curve at eta_i {eta_i:g}")
        return target[matches[0]].tolist()
    return target[0].tolist()


def _measured_nk_or_refuse(record: FitRecord) -> SpectralNK:
    nk = measured_nk(record)
    if nk is None:
        raise ValueError(f"fit {record.id} has no n, k to compare against")
    return nk
