"""
Curve edits the model can follow (fitting.fits.curves): the fit stays within
[0, 1] over its whole domain, also for extreme edits (a penalty constraint
in the least squares, fitting.fits.solver.fit_coefficients ``range_check``); the
reported figures are over the whole blended target with the place of the
largest miss; a single-curve edit leaves far eta_i rows at the base; and on
a set of edits the default refit is at least as close to the whole blended
target as the paper's own method (plain rgb least squares on it).
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting import (
    RGBCurve,
    coated_conductor_model,
    curve_base_from_nk,
    delta_E_map,
    edited_target,
    fit_coefficients,
    fit_curves,
    library_material,
)
from fitting.fits.curves import SCORE_GRID, score_grid, whole_target_error
from fitting.fits.curves_guard import AUDIT_SAMPLES

ANGLES = np.linspace(0.0, 90.0, 46)
MU = np.where(ANGLES == 90.0, 0.0, np.cos(np.radians(ANGLES)))


def base_of(material):
    return curve_base_from_nk(library_material(material), (1.0, 2.5))


def pulled(base, eta_i, channel, angle, value, scale_all=None):
    """The base at eta_i with a bump pulling `channel` at `angle` to `value` (or all scaled)."""
    rgb = base.rgb(MU, eta_i).copy()
    w = np.exp(-0.5 * ((ANGLES - angle) / 9.0) ** 2) * (1 - (ANGLES / 90) ** 6)
    w /= w.max()
    if scale_all is not None:
        rgb *= 1.0 + (scale_all - 1.0) * w[:, None]
    else:
        i = int(np.argmin(np.abs(ANGLES - angle)))
        rgb[:, channel] += (value - rgb[i, channel]) * w
    return RGBCurve.from_angles(eta_i, ANGLES, np.clip(rgb, 0.0, 1.0))


def dense_range(result):
    theta = np.linspace(0.0, 90.0, 181)
    mu = np.where(theta == 90.0, 0.0, np.cos(np.radians(theta)))
    E, M = np.meshgrid(np.linspace(1.0, 2.5, 121), mu, indexing="ij")
    F = coated_conductor_model(M, E, result.packed.coefficients, result.packed.eta_i_range)
    return F.min(), F.max()


@pytest.mark.slow  # 22.5 s (all cases 33.1 s) in a --durations=0 run
@pytest.mark.parametrize(
    "material, edits",
    [
        ("Au", [(1.5, 0, 60, 0.0)]),  # a point pulled to 0
        ("Ag", [(1.5, 2, 40, 0.2), (2.4, 1, 70, 1.0)]),  # a bright metal darkened, and pulled to 1
        ("Cu", [(1.0, 0, 78, 0.0), (2.5, 2, 20, 1.0)]),  # opposite extremes at both ends
    ],
)
def test_extreme_edits_stay_in_range(material, edits):
    base = base_of(material)
    curves = [pulled(base, *edit) for edit in edits]
    result = fit_curves(curves, base)
    low, high = dense_range(result)
    # The documented range promise is 1e-4 over on the fit's check grid
    # (docs/editor.md); this dense 181 x 121 grid also samples between its
    # points, where the float16 model may bulge by as much again: 2e-4.
    assert low >= -2e-4 and high <= 1.0 + 2e-4, (low, high)
    target = result.metrics["target"]
    # Beyond the model's reach: the largest miss is reported with its place.
    assert target["delta_E_max"] > 3.0  # the warning threshold (docs/editor.md), not precision
    assert 0.0 <= target["at_theta_deg"] <= 90.0 and 1.0 <= target["at_eta_i"] <= 2.5
    assert target["grid"] == f"{SCORE_GRID[0]} angles x {SCORE_GRID[1]} eta_i"


@pytest.mark.slow  # 4.3 s in a --durations=0 run under load
def test_reported_figures_are_over_the_whole_blended_target():
    base = base_of("Au")
    curves = [pulled(base, 1.5, 0, 50, 0.6)]
    result = fit_curves(curves, base)
    theta, rows, M, E = score_grid(base.eta_i_range)
    again = whole_target_error(base, curves, result.packed.coefficients, 0.5)
    assert result.metrics["target"] == again
    target = edited_target(base, curves, M, E, 0.5)
    dE = delta_E_map(target, coated_conductor_model(M, E, result.packed.coefficients, base.eta_i_range))
    # The same Delta E by another path (~1e-12 per sample): tightened from
    # approx's default rel=1e-6 to the 1e-9 of the other recomputed figures.
    assert again["delta_E_mean"] == pytest.approx(float(dE.mean()), rel=1e-9)
    assert again["delta_E_max"] == pytest.approx(float(dE.max()), rel=1e-9)


@pytest.mark.slow  # 2.6 s of CPU in a --durations run (a full refit)
def test_single_curve_edit_leaves_far_rows_at_the_base():
    base = base_of("Au")
    curves = [pulled(base, 1.5, 0, 50, 0.7)]
    result = fit_curves(curves, base)
    # The blended target is the base beyond the blend width (0.5) ...
    far = np.array([1.0, 2.1, 2.5])
    E, M = np.meshgrid(far, MU, indexing="ij")
    np.testing.assert_allclose(
        edited_target(base, curves, M, E, 0.5), np.clip(base.rgb(M, E), 0, 1), atol=1e-12
    )  # blend
    # weight exactly 0: only a few roundings of values <= 1
    # ... and the fit stays close to it there (well under a visible difference).
    E, M = np.meshgrid(np.linspace(2.1, 2.5, 5), MU, indexing="ij")
    model = coated_conductor_model(M, E, result.packed.coefficients, base.eta_i_range)
    dE = delta_E_map(base.rgb(M, E), model)
    assert dE.mean() < 1.0, dE.mean()  # fit-quality claim, not precision


def paper_method(base, curves):
    _, _, M, E = score_grid(base.eta_i_range)
    target = edited_target(base, curves, M, E, 0.5)
    C = fit_coefficients(target.reshape(-1, 3), M.ravel(), E.ravel(), base.eta_i_range, 2, "rgb").coefficients_float16
    return whole_target_error(base, curves, C, 0.5)["delta_E_mean"]


@pytest.mark.parametrize(
    "material, edits",
    [
        ("Au", [(1.5, 0, 50, 0.75)]),
        ("Cu", [(1.5, 1, 36, None, 0.8), (1.2, 1, 36, None, 0.8)]),
        ("Al", [(1.5, 2, 60, 0.5)]),
        ("Cr", [(1.5, 0, 55, 0.5), (1.2, 1, 60, 0.4), (2.0, 2, 66, 0.3), (2.4, 0, 72, 0.2)]),
    ],
)
@pytest.mark.slow  # 1.6-7.4 s a case (refits of four metals) in a --durations=0 run under load
def test_default_refit_is_at_least_as_close_as_the_papers_method(material, edits):
    """
    The refit's mean over the whole edited target is no worse than the paper
    method's fitted on the same grid, on the dense grid an auditor uses
    (AUDIT_SAMPLES x AUDIT_SAMPLES, where the guard judges), within the
    tolerance the guard is held to (0.005). On the editor's coarser score
    grid a paper fit made on that very grid can be ahead by that much (Cu's
    edit: 0.6437 against 0.6419, while on the dense grid the refit is ahead).
    """
    base = base_of(material)
    curves = [pulled(base, *edit) for edit in edits]
    ours = fit_curves(curves, base).packed.coefficients
    _, _, M, E = score_grid(base.eta_i_range, (AUDIT_SAMPLES, AUDIT_SAMPLES))
    target = edited_target(base, curves, M, E, 0.5)
    paper = fit_coefficients(
        target.reshape(-1, 3), M.ravel(), E.ravel(), base.eta_i_range, 2, "rgb"
    ).coefficients_float16

    def mean(C):
        return float(delta_E_map(target, coated_conductor_model(M, E, C, base.eta_i_range)).mean())

    assert mean(ours) <= mean(paper) + 0.005


def test_range_check_is_validated():
    mu = np.linspace(0, 1, 10)
    target = np.full((10, 3), 0.5)
    with pytest.raises(ValueError, match="range_check"):
        fit_coefficients(target, mu, np.full(10, 1.5), (1.0, 2.5), 2, "rgb", range_check=(mu, mu[:3], 10.0))
    with pytest.raises(ValueError, match="weight"):
        fit_coefficients(target, mu, np.full(10, 1.5), (1.0, 2.5), 2, "rgb", range_check=(mu, mu, -1.0))
