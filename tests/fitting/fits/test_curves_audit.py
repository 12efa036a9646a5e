"""
Curve refits against the paper's method as an auditor runs it (rgb least squares on the
100 x 100 grid of the whole target, from several starts), and the warning of an edit the
model cannot follow.
"""

from __future__ import annotations

import pytest

from benchmarks.curve_edits_hard import EDITS, edit_curve
from fitting import curve_base_from_nk, fit_curves, library_material
from fitting.fits.curves_guard import AUDIT_STARTS, FOLLOW_MAX, FOLLOW_MEAN, edit_warnings


def test_edit_warnings_name_where_and_by_how_much():
    rows = [{"eta_i": 1.5, "delta_E_mean": 18.6, "delta_E_max": 24.0},
            {"eta_i": 2.0, "delta_E_mean": 0.2, "delta_E_max": 0.9},
            {"eta_i": 1.2, "delta_E_mean": 0.5, "delta_E_max": FOLLOW_MAX + 0.1}]
    first, second = edit_warnings(rows)
    assert first.startswith("edit not followed: the fit stays 18.60 mean Delta E 2000 from the edited "
                            "curve at eta_i 1.5 (max 24.00)")
    assert "eta_i 1.2" in second
    assert edit_warnings([{"eta_i": 1.5, "delta_E_mean": FOLLOW_MEAN, "delta_E_max": FOLLOW_MAX}]) == []


def _refit(label):
    _, material, specs, _ = next(edit for edit in EDITS if edit[0] == label)
    base = curve_base_from_nk(library_material(material), (1.0, 2.5))
    return fit_curves([edit_curve(base, eta, *spec) for eta, *spec in specs], base)


@pytest.mark.slow  # one refit with its guard: about 5 s
def test_a_blue_pull_the_model_cannot_follow_is_said():
    result = _refit("Mo blue pulled near 0")
    (warning,) = result.metrics["warnings"]
    assert "eta_i 1.5" in warning and "cannot bend that way" in warning


@pytest.mark.slow  # one refit with its guard: about 5 s
def test_a_steep_step_is_no_worse_than_the_auditors_fit():
    guard = _refit("Ni steep red step").metrics["guard"]
    audit = guard["audit"]
    assert audit["grid"] == "100 x 100" and audit["starts"] == list(AUDIT_STARTS)
    assert audit["in_range"]
    chosen = guard["candidates"][guard["chosen"]]
    assert chosen["delta_E_mean"] <= audit["delta_E_mean"] + 0.005
    assert chosen["delta_E_max"] <= audit["delta_E_max"] + 0.05
