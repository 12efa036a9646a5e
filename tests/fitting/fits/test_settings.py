"""fitting.fits.settings: the fitting grid and settings."""

import numpy as np
import pytest

from fitting.fits.settings import FitSettings, fit_grid

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


class TestFitGrid:
    def test_gauss_weights_integrate_polynomials(self):
        mu, eta, w = fit_grid((1.0, 2.5), 4, 3)
        # Mean of w f over the grid = the mean of f over the domain, exactly
        # for degree <= 2n - 1 per axis.
        f = mu**7 * (eta - 1.0) ** 5
        exact = (1.0 / 8.0) * (1.5**6 / 6.0) / 1.5
        assert np.mean(w * f) == pytest.approx(exact, rel=1e-12)  # Gauss
        # nodes and weights to ~10 u64 each, 12 terms in the mean: < 1e3 u64 = 1.1e-13

    def test_grids_are_the_callers_own(self):
        # The Gauss nodes are computed once per size: a caller writing into
        # one grid changes no later grid.
        first = fit_grid((1.0, 2.5), 6, 3)
        expected = [a.copy() for a in first]
        for a in first:
            a *= 2.0
        for a, b in zip(fit_grid((1.0, 2.5), 6, 3), expected):
            assert np.array_equal(a, b)
        x, w = np.polynomial.legendre.leggauss(6)
        assert np.array_equal(expected[0][:6], 0.5 * (x + 1.0))

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
