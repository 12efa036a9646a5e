"""The small trust-region solver against scipy's ``least_squares(method="trf")``, whose iteration it is."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from fitting.numerics import trf_least_squares


def _exponentials():
    """A sum of two decaying exponentials fitted to noisy samples (4 unknowns, 60 residuals)."""
    t = np.linspace(0.0, 4.0, 60)
    rng = np.random.default_rng(3)
    y = 2.0 * np.exp(-1.3 * t) + 0.5 * np.exp(-0.2 * t) + 0.01 * rng.standard_normal(t.size)

    def fun(x):
        return x[0] * np.exp(-x[1] * t) + x[2] * np.exp(-x[3] * t) - y

    def jac(x):
        e1, e3 = np.exp(-x[1] * t), np.exp(-x[3] * t)
        return np.stack([e1, -x[0] * t * e1, e3, -x[2] * t * e3], axis=1)

    return fun, jac, np.array([1.0, 1.0, 1.0, 0.1])


def _rosenbrock():
    def fun(x):
        return np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]])

    def jac(x):
        return np.array([[-20.0 * x[0], 10.0], [-1.0, 0.0]])

    return fun, jac, np.array([-1.2, 1.0])


class TestTrfLeastSquares:
    @pytest.mark.parametrize("problem", [_exponentials, _rosenbrock])
    def test_the_iterates_of_scipy(self, problem):
        """The same steps as scipy's trf (x_scale='jac'): the same evaluations and optimum."""
        fun, jac, x0 = problem()
        ours = trf_least_squares(fun, jac, x0, 1e-10, 1e-10, 1e-10, 200)
        theirs = least_squares(
            fun, x0, jac=jac, method="trf", x_scale="jac", ftol=1e-10, xtol=1e-10, gtol=1e-10, max_nfev=200
        )
        assert (ours.nfev, ours.njev, ours.status) == (theirs.nfev, theirs.njev, theirs.status)
        np.testing.assert_allclose(ours.x, theirs.x, rtol=1e-9, atol=1e-12)
        assert ours.cost == pytest.approx(theirs.cost, rel=1e-9, abs=1e-15)
        assert ours.success and ours.message == theirs.message

    def test_out_of_evaluations_is_reported(self):
        fun, jac, x0 = _rosenbrock()
        result = trf_least_squares(fun, jac, x0, 1e-12, 1e-12, 1e-12, max_nfev=3)
        assert result.nfev == 3 and result.status == 0 and not result.success
        assert "maximum number of function evaluations" in result.message

    def test_rank_deficient(self):
        """Two unknowns that only their sum identifies: a finite minimiser of least norm step, cost 0."""

        def fun(x):
            return np.array([x[0] + x[1] - 1.0, 2.0 * (x[0] + x[1] - 1.0)])

        def jac(x):
            return np.array([[1.0, 1.0], [2.0, 2.0]])

        result = trf_least_squares(fun, jac, np.array([3.0, -5.0]), 1e-12, 1e-12, 1e-12, 100)
        assert np.all(np.isfinite(result.x)) and result.cost < 1e-20

    def test_non_finite_trial_shrinks_the_region(self):
        """A step to where f is not finite is refused, not taken."""

        def fun(x):
            return np.array([np.log(x[0]) - 1.0]) if x[0] > 0 else np.array([np.nan])

        def jac(x):
            return np.array([[1.0 / x[0]]])

        result = trf_least_squares(fun, jac, np.array([0.05]), 1e-12, 1e-12, 1e-12, 100)
        assert result.x[0] == pytest.approx(np.e, rel=1e-8)

    def test_a_jacobian_not_finite_stops_the_solve(self):
        """A Jacobian with a NaN is reported (status -1), never looped on."""

        def fun(x):
            return np.array([x[0] - 1.0, x[1] - 2.0])

        def jac(x):
            return np.array([[1.0, 0.0], [0.0, np.nan]])

        result = trf_least_squares(fun, jac, np.array([0.0, 0.0]), 1e-12, 1e-12, 1e-12, 100)
        assert result.status == -1 and not result.success and "not finite" in result.message
