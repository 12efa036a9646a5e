"""fitting.fits.solver: fit_coefficients on known models."""

import numpy as np
import pytest

from fitting.colour.reference import reference_ACEScg
from fitting.fits.material import fit_material
from fitting.fits.objective import Problem
from fitting.fits.settings import FitSettings, fit_grid
from fitting.fits.solver import fit_coefficients
from fitting.fits.start import ALPHA_CANDIDATES, initial_guess
from fitting.models.coated_conductor import coated_conductor_model
from fitting.optics.library import library_material

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

KNOWN = np.array(
    [
        [[0.9, -0.1, 0.04], [0.75, -0.18, 0.1], [0.42, -0.2, 0.12]],
        [[0.3, -0.4, 0.2], [0.5, -0.8, 0.3], [0.6, -1.0, 0.4]],
        [[6.0, -1.0, 0.5], [5.0, 0.5, -0.2], [4.0, 1.0, 0.3]],
    ]
)


class TestProblem:
    @pytest.mark.parametrize("objective", ["rgb", "lab", "de2000"])
    @pytest.mark.parametrize("weighted", [False, True])
    def test_residuals_jacobian_is_both_in_one_pass(self, objective, weighted):
        # The one pass (SLSQP's evaluation in fitting/fits/constrained.py) computes
        # Eq. 1, Lab and its derivative in another order than residuals() and
        # jacobian(): a few roundings of values up to ~100 (Lab) times the
        # CIEDE2000 weights: 1e-11 absolute (2^-53 * 100 * 16 = 1.8e-13 per
        # rounding, a 50x margin); the Jacobian, entries up to ~300, 1e-10.
        mu, eta, _ = fit_grid((1.0, 2.5), 16, 5, "uniform")
        mu = np.concatenate([mu, [0.0, 1.0]])  # grazing and normal: log(1 - mu) at 0
        eta = np.concatenate([eta, [2.5, 1.0]])
        target = coated_conductor_model(mu, eta, KNOWN) * 0.97
        weights = np.linspace(0.5, 2.0, mu.size) if weighted else None
        problem = Problem(target, mu, eta, (1.0, 2.5), 2, objective, weights)
        x = (KNOWN + 0.01).ravel()
        r, J = problem.residuals_jacobian(x)
        np.testing.assert_allclose(r.ravel(), problem.residuals(x), rtol=0, atol=1e-11)
        np.testing.assert_allclose(J.reshape(r.size, -1), problem.jacobian(x), rtol=0, atol=1e-10)

    @pytest.mark.parametrize("objective", ["rgb", "lab", "de2000"])
    @pytest.mark.parametrize("weighted", [False, True])
    def test_deferred_jacobian_is_the_one_pass_to_the_bit(self, objective, weighted):
        # SLSQP's line-search points take the values alone (fitting/fits/constrained.py):
        # the same operations on the same values, so exactly the one pass's.
        mu, eta, _ = fit_grid((1.0, 2.5), 16, 5, "uniform")
        target = coated_conductor_model(mu, eta, KNOWN) * 0.97
        weights = np.linspace(0.5, 2.0, mu.size) if weighted else None
        problem = Problem(target, mu, eta, (1.0, 2.5), 2, objective, weights)
        x = (KNOWN + 0.01).ravel()
        r, J = problem.residuals_jacobian(x)
        d, jacobian = problem.residuals_deferred(x)
        problem.residuals_deferred(x + 0.5)  # another point between: the first keeps its own
        assert np.array_equal(d, r) and np.array_equal(jacobian(), J)

    @pytest.mark.parametrize("objective", ["lab", "de2000"])
    @pytest.mark.parametrize("checked", [False, True])
    def test_jacobian_after_residuals_is_the_one_pass_to_the_bit(self, objective, checked):
        # lab and de2000 residuals are the one pass's, and trf asks for the
        # Jacobian at the point whose residuals it has just evaluated:
        # residuals() keeps the one pass's Jacobian for that x.
        mu, eta, _ = fit_grid((1.0, 2.5), 16, 5, "uniform")
        target = coated_conductor_model(mu, eta, KNOWN) * 0.97
        check = (np.linspace(0.0, 1.0, 7), np.full(7, 1.7), 3.0) if checked else None
        weights = np.linspace(0.5, 2.0, mu.size)
        problem = Problem(target, mu, eta, (1.0, 2.5), 2, objective, weights, check)
        fresh = Problem(target, mu, eta, (1.0, 2.5), 2, objective, weights, check)
        x, y = (KNOWN + 0.01).ravel(), (KNOWN * 1.5).ravel()  # at y the range rows are active
        r, J = fresh.residuals_jacobian(x)
        assert np.array_equal(problem.residuals(x)[: r.size], r.ravel())
        assert np.array_equal(problem.jacobian(x)[: r.size], J.reshape(r.size, -1))
        # At another point the Jacobian is that point's, not the one kept.
        assert np.array_equal(problem.jacobian(y), fresh.jacobian(y))
        problem.residuals(x)
        assert np.array_equal(problem.jacobian(y), fresh.jacobian(y))
        if checked:
            assert np.array_equal(problem.residuals(y), fresh.residuals(y))
            assert np.any(problem.residuals(y)[3 * mu.size :] != 0.0)

    @pytest.mark.parametrize("objective", ["rgb", "lab", "de2000"])
    def test_reweighted_is_the_problem_with_those_weights(self, objective):
        # The rounds of reweighting share the target's Lab, its metric and the geometry.
        mu, eta, _ = fit_grid((1.0, 2.5), 16, 5, "uniform")
        target = coated_conductor_model(mu, eta, KNOWN) * 0.97
        x = (KNOWN + 0.01).ravel()
        first = Problem(target, mu, eta, (1.0, 2.5), 2, objective)
        first.residuals(x), first.jacobian(x)
        weights = np.linspace(0.5, 2.0, mu.size)
        again = first.reweighted(weights)
        fresh = Problem(target, mu, eta, (1.0, 2.5), 2, objective, weights)
        assert np.array_equal(again.residuals(x), fresh.residuals(x))
        assert np.array_equal(again.jacobian(x), fresh.jacobian(x))
        assert np.array_equal(first.residuals(x), Problem(target, mu, eta, (1.0, 2.5), 2, objective).residuals(x))


class TestFitCoefficients:
    @pytest.mark.parametrize("objective", ["rgb", "lab", "de2000"])
    def test_recovers_known_coefficients(self, objective):
        mu, eta, _ = fit_grid((1.0, 2.5), 32, 9, "uniform")
        target = coated_conductor_model(mu, eta, KNOWN)
        result = fit_coefficients(target, mu, eta, (1.0, 2.5), objective=objective)
        assert result.success
        recovered = coated_conductor_model(mu, eta, result.coefficients)
        # Not rounding: the solver stops at ftol = xtol = gtol = 1e-10
        # (fitting/fits/solver.py) on an exactly representable target; 1e-6
        # in reflectance is the convergence claim. The coefficients are less
        # well determined (only the F0 and a rows are checked): 1e-3 is that claim.
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


class TestInitialGuess:
    def test_each_rung_as_its_own_least_squares(self):
        """The stacked normal equations give each rung's lstsq solution; the best rung per channel wins."""
        mu, eta, _ = fit_grid((1.0, 2.5), 12, 4)
        target = reference_ACEScg(library_material("Cu"), mu, eta, 5.0)
        x0 = initial_guess(target, mu, eta, (1.0, 2.5), 2)
        t = (eta - 1.0) / 1.5
        T = np.stack([t**j for j in range(3)], axis=-1)
        x = 1.0 - mu
        for c in range(3):
            alpha = x0[2, c, 0]
            assert alpha in ALPHA_CANDIDATES and np.all(x0[2, c, 1:] == 0.0)
            basis = np.concatenate([(1.0 - x**5)[:, None] * T, -(mu * x**alpha)[:, None] * T], axis=1)
            coef = np.linalg.lstsq(basis, target[:, c] - x**5, rcond=None)[0]
            np.testing.assert_allclose(np.concatenate([x0[0, c], x0[1, c]]), coef, rtol=1e-9, atol=1e-11)

    def test_rank_deficient_basis(self):
        """Every sample at normal incidence (the exponent term vanishes): finite, F0 fitted, a zero."""
        x0 = initial_guess(np.full((8, 3), 0.5), np.ones(8), np.linspace(1.0, 2.0, 8), (1.0, 2.0), 2)
        assert np.all(np.isfinite(x0))
        np.testing.assert_allclose(x0[0, :, 0], 0.5)
        np.testing.assert_allclose(x0[1], 0.0, atol=1e-12)
