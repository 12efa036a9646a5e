"""
What a curve fit was fitted to
==============================

-   :func:`target_at`: a curve fit's target at one eta_i (the blended edited
    target with a base, else the curve at that eta_i).
-   :func:`error_map`: Delta E 2000 of a stored fit over (eta_i, angle)
    against what it was fitted to: the spectral reference of its n, k, the
    edited target, or the curves themselves.
-   :func:`snap_to_domain`: curves within float32 rounding of a bound of the
    base's domain moved onto it (the domain is stored as float32).

Both rebuild the target from the request kept in the fit's provenance
(:mod:`service.jobs.curves`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fitting.colour.delta_e import delta_E_map
from fitting.domain import cos_theta_from_angle
from fitting.fits.curves import CurveFitSettings
from fitting.fits.curves_base import curve_base_from_coefficients, curve_base_from_nk, edited_target
from fitting.fits.curves_input import check_curves
from fitting.models.kinds import DEFAULT_MODEL, model_ACEScg
from fitting.models.pack import material_from_json
from fitting.optics.nk import SpectralNK

from ..store import FitRecord
from .common import measured_nk

__all__ = ["snap_to_domain", "target_at", "error_map"]

DEFAULTS = CurveFitSettings()


def snap_to_domain(curves: list[dict], domain: tuple[float, float]) -> list[dict]:
    """Curves within float32 rounding of a bound of ``domain`` moved onto it."""
    lo, hi = domain
    out = []
    for curve in curves:
        eta = curve["eta_i"]
        for bound in (lo, hi):
            if eta != bound and np.float32(eta) == np.float32(bound):
                curve = {**curve, "eta_i": bound}
        out.append(curve)
    return out


def _measured_nk_or_refuse(record: FitRecord) -> SpectralNK:
    nk = measured_nk(record)
    if nk is None:
        raise ValueError(f"fit {record.id} has no n, k to compare against")
    return nk


def _target_of(record: FitRecord, mu: np.ndarray, eta: np.ndarray):
    """(eta_i rows, target (E, M, 3), against) for a stored fit."""
    domain = material_from_json(record.material).eta_i_range
    provenance = record.provenance or {}
    if record.kind == "curves":
        request = provenance.get("request", {})
        curves = check_curves(snap_to_domain(request.get("curves", []), domain))
        base = provenance.get("base")
        if base is None:
            rows = np.array(sorted(c.eta_i for c in curves))
            target = np.stack([next(c for c in curves if c.eta_i == e).sampled(mu) for e in rows])
            return rows, target, "curves"
        if base["kind"] == "model":
            grid = curve_base_from_coefficients(
                np.asarray(base["coefficients"]), domain, base["name"], model=base.get("model", DEFAULT_MODEL)
            )
        else:
            grid = curve_base_from_nk(_measured_nk_or_refuse(record), domain)
        E, M = np.meshgrid(eta, mu, indexing="ij")
        width = request.get("blend_width", DEFAULTS.blend_width)
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


def error_map(record: FitRecord, angles: int, rows: int) -> dict[str, Any]:
    """
    Delta E 2000 of the fit's float16 model against what it was fitted to:
    the spectral reference (5 nm) of its n, k, or for a curve fit the edited
    target (with a base) or the curves themselves (rows at their eta_i).
    """
    packed = material_from_json(record.material)
    lo, hi = packed.eta_i_range
    theta = np.linspace(0.0, 90.0, angles)
    mu = cos_theta_from_angle(theta)
    eta = np.linspace(lo, hi, rows) if hi > lo else np.array([lo])
    eta, target, against = _target_of(record, mu, eta)
    E, M = np.meshgrid(eta, mu, indexing="ij")
    model = model_ACEScg(packed.model, M, E, packed.coefficients, packed.eta_i_range)
    dE = delta_E_map(target, model)
    return {
        "fit_id": record.id,
        "against": against,
        "theta_deg": theta.tolist(),
        "eta_i": eta.tolist(),
        "delta_E": np.round(dE, 4).tolist(),
        "delta_E_mean": float(dE.mean()),
        "delta_E_max": float(dE.max()),
    }
