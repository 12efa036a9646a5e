"""
Scoring of curve fits
=====================

-   :data:`SCORE_GRID`, :func:`score_grid`: where a curve fit's figures are
    measured, the whole blended target (as the editor's error map).
-   :func:`whole_target_error`: Delta E 2000 of a model against the whole
    blended target there.
-   :func:`check_grid`: where a curve fit must stay in [0, 1].
-   :func:`angle_mu`: cos theta of angles in degrees, exactly 0 at 90.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab
from ..colour.delta_e import delta_E_2000
from ..models.kinds import DEFAULT_MODEL, model_ACEScg
from .curves_base import CurveBase, edited_target
from .curves_input import RGBCurve
from .metrics import AGAINST_CURVES
from ..numerics.plain import union

__all__ = ["SCORE_GRID", "score_grid", "whole_target_error", "check_grid", "angle_mu"]

SCORE_GRID = (46, 31)
"""(angles evenly over [0, 90] degrees, eta_i rows evenly over the domain):
where a curve fit's ``target`` figures are measured, the whole blended
target, as the editor's error map."""


def angle_mu(theta_deg: np.ndarray) -> np.ndarray:
    return np.where(theta_deg == 90.0, 0.0, np.cos(np.radians(theta_deg)))


def score_grid(eta_i_range, shape=SCORE_GRID) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(theta_deg (A,), eta_i (E,), and the meshes mu, eta (E, A)) of the scoring grid."""
    lo, hi = eta_i_range
    theta = np.linspace(0.0, 90.0, shape[0])
    rows = np.linspace(lo, hi, shape[1]) if hi > lo else np.array([lo])
    E, T = np.meshgrid(rows, theta, indexing="ij")
    return theta, rows, angle_mu(T), E


def check_grid(eta_i_range, angles: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """
    (mu, eta) meshes where the fit must stay in [0, 1]: ``angles`` evenly
    over [0, 90] degrees plus every 0.5 degree from 80 to 89.5 (the model
    can overshoot 1 just before grazing, where it meets 1), ``rows`` eta_i.
    """
    lo, hi = eta_i_range
    theta = union(np.linspace(0.0, 90.0, angles), np.arange(80.0, 90.0, 0.5))
    eta = np.linspace(lo, hi, rows) if hi > lo else np.array([lo])
    E, T = np.meshgrid(eta, theta, indexing="ij")
    return angle_mu(T), E


_LAST: list = [None]


def _scored_target(base, curves, blend_width, shape):
    """
    The scoring grid and the whole blended target's Lab there, kept for the
    last ``base`` and ``curves`` objects (the same objects, curve by curve):
    a refit scores several candidates against one target (its result, the
    fit on screen, a fallback).
    """
    objects, values = (base, *curves), (float(blend_width), tuple(shape))
    last = _LAST[0]
    if (
        last is None
        or len(last[0]) != len(objects)
        or last[1] != values
        or not all(a is b for a, b in zip(last[0], objects))
    ):
        grid = score_grid(base.eta_i_range, shape)
        last = _LAST[0] = (
            objects,
            values,
            grid,
            ACEScg_to_Lab(edited_target(base, curves, grid[2], grid[3], blend_width)),
        )
    return last[2], last[3]


def whole_target_error(
    base: CurveBase,
    curves: Sequence[RGBCurve],
    coefficients,
    blend_width: float,
    shape=SCORE_GRID,
    model: str = DEFAULT_MODEL,
) -> dict[str, Any]:
    """
    Delta E 2000 of the model (of kind ``model``) of ``coefficients`` against the whole blended
    target (:func:`edited_target`) on the scoring grid: ``against`` in words,
    mean, max and where the max is (``max_at``; also ``at_theta_deg``,
    ``at_eta_i``), and the model's range there.
    """
    (theta, rows, M, E), target_Lab = _scored_target(base, curves, blend_width, shape)
    RGB = model_ACEScg(model, M, E, coefficients, base.eta_i_range)
    dE = delta_E_2000(target_Lab, ACEScg_to_Lab(RGB))
    j, i = np.unravel_index(int(np.argmax(dE)), dE.shape)
    grid = f"{theta.size} angles x {rows.size} eta_i"
    return {
        "against": f"{AGAINST_CURVES} (the whole edited target, {grid})",
        "delta_E_mean": float(dE.mean()),
        "delta_E_max": float(dE.max()),
        "max_at": {"eta_i": float(rows[j]), "theta_deg": float(theta[i])},
        "at_theta_deg": float(theta[i]),
        "at_eta_i": float(rows[j]),
        "model_min": float(RGB.min()),
        "model_max": float(RGB.max()),
        "grid": grid,
    }
