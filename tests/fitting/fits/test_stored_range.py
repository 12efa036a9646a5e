"""Every stored fit's model lies in [0, 1]: proven, and on a 10^4-point dense evaluation."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from fitting import LIBRARY_NAMES, curve_base_from_nk, fit_curves, fit_material, library_material
from fitting.fits.curves_score import score_grid
from fitting.fits.curves_base import edited_target
from fitting.fits.solver import fit_coefficients
from fitting.colour.delta_e import delta_E_map
from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import pack_from_json
from fitting.models.range_bound import RANGE_SLACK, certify_range

ROOT = Path(__file__).resolve().parents[3]


def dense_range(C, domain):
    """min and max of the model on 100 x 100 (cos theta, eta_i) over the domain: 10^4 points."""
    E, M = np.meshgrid(np.linspace(*domain, 100), np.linspace(0.0, 1.0, 100), indexing="ij")
    F = coated_conductor_model(M, E, C, domain)
    return F.min(), F.max()


def test_golden_pack_is_in_range():
    (material,) = pack_from_json((ROOT / "tests/golden/Au_golden.json").read_text())
    lo, hi = dense_range(material.coefficients, material.eta_i_range)
    # RANGE_SLACK: float16 rounding at the boundary (fitting/models/range_bound.py).
    assert -RANGE_SLACK <= lo and hi <= 1.0 + RANGE_SLACK
    assert certify_range(material.coefficients, material.eta_i_range).in_range is True


@pytest.mark.slow  # 22 fits
def test_library_fits_are_proven_in_range():
    for name in LIBRARY_NAMES:
        result = fit_material(library_material(name))
        lo, hi = dense_range(result.coefficients_float16, result.eta_i_range)
        assert -RANGE_SLACK <= lo and hi <= 1.0 + RANGE_SLACK, name
        assert result.quality["range"]["in_range"] is True, name


@pytest.mark.slow  # curve refits take seconds
@pytest.mark.numeric
def test_au_green_pulled_to_002_at_80_degrees():
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from curve_edits_vs_paper import edit_curve

    base = curve_base_from_nk(library_material("Au"))
    curve = edit_curve(base, 1.5, "to", 1, 80.0, 0.02)
    result = fit_curves([curve], base)
    C16 = result.coefficients_float16
    lo, hi = dense_range(C16, base.eta_i_range)
    assert -RANGE_SLACK <= lo and hi <= 1.0 + RANGE_SLACK
    assert result.metrics["range"]["in_range"] is True
    # Mean and max on the whole blended target no worse than the paper's method there
    # (rgb least squares on the scoring grid, as benchmarks/curve_edits_vs_paper.py) when
    # that fit is a reflectance; here it leaves [0, 1] (max Delta E 16.8, a model above 1),
    # so the bar is the paper's method held in [0, 1], the guard's `rgb` candidate. Known
    # gap: no in-range refit reaches the out-of-range fit's max on this edit.
    _, _, M, E = score_grid(base.eta_i_range)
    target = edited_target(base, [curve], M, E, 0.5)
    paper = fit_coefficients(target.reshape(-1, 3), M.ravel(), E.ravel(), base.eta_i_range, 2, "rgb")
    ours = delta_E_map(target, coated_conductor_model(M, E, C16, base.eta_i_range))
    if certify_range(paper.coefficients_float16, base.eta_i_range).in_range:
        theirs = delta_E_map(target, coated_conductor_model(M, E, paper.coefficients_float16, base.eta_i_range))
        bar = {"delta_E_mean": float(theirs.mean()), "delta_E_max": float(theirs.max())}
    else:
        bar = result.metrics["guard"]["candidates"]["rgb"]
    assert ours.mean() <= bar["delta_E_mean"] and ours.max() <= bar["delta_E_max"]
