"""fitting.numerics.splines against the scipy.interpolate classes they stand in for."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import Akima1DInterpolator, CubicSpline, PchipInterpolator

from fitting.numerics.splines import akima, cubic_spline, pchip
from fitting.optics.library import LIBRARY, library_material

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

PAIRS = [(pchip, PchipInterpolator), (akima, Akima1DInterpolator), (cubic_spline, CubicSpline)]
IDS = ["pchip", "akima", "not-a-knot"]


def _agree(ours, theirs, x, y):
    xi = np.concatenate([x, np.linspace(x[0], x[-1], 997)])
    expected = theirs(x, y)(xi)
    got = ours(x, y)(xi)
    # Rounding only: the same cubics, summed in another order (and the spline's slopes by
    # another elimination): relative to the data's scale, times the condition of the solve.
    scale = np.max(np.abs(y)) + 1.0
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-11 * scale)


@pytest.mark.parametrize("ours, theirs", PAIRS, ids=IDS)
class TestAgainstScipy:
    def test_random_uneven_data(self, ours, theirs):
        rng = np.random.default_rng(7)
        for n in (2, 3, 4, 5, 8, 33, 200):
            for _ in range(5):
                x = np.cumsum(rng.uniform(0.01, 3.0, n)) + rng.uniform(-50, 50)
                y = rng.normal(size=n) * rng.choice([1e-3, 1.0, 1e3])
                _agree(ours, theirs, x, y)

    def test_flat_runs_steps_and_turns(self, ours, theirs):
        x = np.array([0.0, 1.0, 2.0, 2.5, 4.0, 7.0, 7.1, 9.0, 10.0])
        for y in (
            np.array([0, 0, 0, 1, 1, 1, 0, 0, 0], dtype=float),
            np.array([1, 2, 3, 3, 2, 5, 5, 5, 4], dtype=float),
            np.array([0, 1, 0, 1, 0, 1, 0, 1, 0], dtype=float),
            np.full(9, 2.5),
            np.linspace(-3, 3, 9) ** 3,
        ):
            _agree(ours, theirs, x, y)

    def test_library_data_as_the_uncertainty_reads_it(self, ours, theirs):
        for name in LIBRARY:
            nk = library_material(name)
            w = nk.wavelength_nm
            _agree(ours, theirs, w, np.log(nk.n))
            _agree(ours, theirs, w, np.log(nk.k + 1e-3))


@pytest.mark.parametrize("ours", [pchip, akima, cubic_spline], ids=IDS)
def test_bad_input_is_refused_by_name(ours):
    with pytest.raises(ValueError, match="`x` must be strictly increasing"):
        ours([0.0, 2.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="`x` must have at least 2 samples"):
        ours([0.0], [1.0])
    with pytest.raises(ValueError, match="`x` and `y` must be 1-D of one length"):
        ours([0.0, 1.0], [1.0, 2.0, 3.0])
