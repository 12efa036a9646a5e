"""The fit pipeline's stages: the same fit as the one call, the reference shared between degrees."""

from __future__ import annotations

import numpy as np

from fitting import library_material
from fitting.fits.kinds import fit_kind, fit_model
from fitting.fits.pipeline import finish_fit, fit_problem, guard_problem, solve_problem


def test_stages_give_the_one_calls_fit_and_assess_on_request():
    nk = library_material("Au")
    problem = fit_problem(fit_kind("coated-conductor"), nk, (1.2, 1.8), degree=2)
    for degree in (1, 2):
        staged = problem.with_degree(degree)
        assert staged.target is problem.target and staged.settings.degree == degree
        result = finish_fit(staged, guard_problem(staged, solve_problem(staged)), assess=False)
        one_call = fit_model(nk, (1.2, 1.8), degree=degree)
        np.testing.assert_array_equal(result.coefficients_float16, one_call.coefficients_float16)
        assert result.guard == one_call.guard
        # Unassessed: the data's warnings only; assessed again: the one call's quality and pack.
        assert set(result.quality) == {"warnings"}
        assert finish_fit(staged, result).quality == one_call.quality
        assert result.packed.source == one_call.packed.source
        assert result.timings["total"] >= result.timings["fit"]
