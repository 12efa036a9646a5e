"""The fit pipeline's stages: the same fit as the one call, the reference shared between degrees."""

from __future__ import annotations

import numpy as np
import pytest

from fitting import library_material
from fitting.fits.kinds import fit_kind, fit_model
from fitting.fits.pipeline import finish_fit, fit_problem, guard_problem, solve_problem


@pytest.mark.slow  # two fits and their assessment: 2-4 s
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


def test_a_scenes_shipped_fit_is_assessed_as_the_one_call_fit_of_its_kind():
    from fitting.fits.scene_fit import fit_scene_material
    from fitting.models.kinds import DEFAULT_MODEL
    from fitting.fits.scene_schema import EtaSpec, SceneMaterial
    from fitting.fits.settings import FitSettings, fit_grid

    # Au's data are sparse: the shipped fit carries the data's uncertainty and its warning.
    nk = library_material("Au")
    entry = SceneMaterial("Au", "Au", nk, EtaSpec("set", (1.0, 2.5)))
    result = fit_scene_material(entry)
    kind, degree = result.choice["model"], result.choice["degree"]
    assert not result.choice["from_general_fit"]
    settings = FitSettings() if kind == DEFAULT_MODEL else fit_kind(kind).settings
    rows = [fit_grid((v, v), settings.mu_samples, 1, settings.grid) for v in (1.0, 2.5)]
    samples = tuple(np.concatenate(parts) for parts in zip(*rows))
    one_call = fit_model(nk, (1.0, 2.5), kind, settings, samples=samples, degree=degree)
    np.testing.assert_array_equal(result.fit.coefficients_float16, one_call.coefficients_float16)
    assert result.fit.quality == one_call.quality and "uncertainty" in result.fit.quality
    assert result.fit.packed.source == one_call.packed.source


@pytest.mark.slow  # three fits with their metrics: about 2 s
def test_metrics_in_float32_as_the_service_evaluates_them():
    """``evaluate="float32"``: the metrics of its float32 reference, within 0.001 Delta E of float64's."""
    nk = library_material("Cu")
    exact, quick = fit_model(nk, evaluate=True), fit_model(nk, evaluate="float32")
    np.testing.assert_array_equal(exact.coefficients_float16, quick.coefficients_float16)
    for figure in ("delta_E_mean", "delta_E_max"):
        assert abs(exact.metrics["model_float16"][figure] - quick.metrics["model_float16"][figure]) < 1e-3
    assert not fit_model(nk, evaluate=False).metrics
    with pytest.raises(ValueError, match="`evaluate` must be a bool or one of float64, float32, got 'float16'"):
        fit_model(nk, evaluate="float16")
