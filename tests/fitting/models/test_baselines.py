"""fitting.models.baselines: Schlick and adjusted Lazanyi."""

import numpy as np
import pytest

from fitting.colour.reference import reference_ACEScg
from fitting.models.baselines import (
    equivalent_index,
    BASELINES,
    MU_BAR,
    baseline_ACEScg,
    baseline_inputs,
    baselines_ACEScg,
    external_medium_F0,
    lazanyi_a,
    lazanyi_adjusted,
    schlick,
)
from fitting.optics.library import library_material
from precision import F64_FEW_OPS, F64_RGB_BOUND

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


class TestBaselines:
    def test_schlick_clamps_and_keeps_nan(self):
        # Never raises on numbers, never NaN for finite input: mu and F0 clamped to [0, 1].
        F = schlick(np.array([-1.0, 0.5, 2.0]), [1e300, -1e300, 0.5])
        assert np.all(np.isfinite(F)) and np.all((F >= 0) & (F <= 1))
        np.testing.assert_array_equal(F[1], schlick(0.5, [1.0, 0.0, 0.5]))
        assert np.isnan(schlick(np.nan, [0.5, 0.5, 0.5])).all()

    def test_schlick(self):
        # Closed forms of a few operations on [0, 1]: within F64_FEW_OPS
        # (tightened from pytest.approx's default rel=1e-6, no derivation).
        assert schlick(1.0, [0.5, 0.5, 0.5]) == pytest.approx([0.5, 0.5, 0.5], rel=F64_FEW_OPS)
        assert schlick(0.0, [0.5, 0.2, 0.1]) == pytest.approx([1, 1, 1], rel=F64_FEW_OPS)

    def test_external_medium_F0_identity_in_air(self):
        F0 = np.array([0.9, 0.7, 0.4])
        # F0 -> sqrt -> n = (1 + s) / (1 - s) -> F0 again: ~10 roundings, the
        # difference 1 - sqrt(F0) of condition <= 1 / (1 - sqrt(0.9)) = 20:
        # 200 u64 = 2.2e-14 < 1e-12 (a 45x margin).
        np.testing.assert_allclose(external_medium_F0(F0, 1.0), F0, rtol=1e-12)
        # A dielectric with n = 1.5 has F0 = 0.04; under eta_i = 1.5 it vanishes.
        # n comes back within ~4 ulps of 1.5, so ((n - 1.5) / (n + 1.5))^2 <= 1e-31.
        assert external_medium_F0([0.04], 1.5)[0] == pytest.approx(0.0, abs=1e-12)

    def test_equivalent_index_gives_F0_in_air(self):
        F0 = np.array([0.0, 0.04, 0.5, 0.95, 1.0])
        n = equivalent_index(F0)
        assert np.all(np.isfinite(n))
        np.testing.assert_allclose(((n - 1.0) / (n + 1.0)) ** 2, np.minimum(F0, 1.0 - 1.0e-6), atol=1e-12)

    def test_lazanyi_passes_through_F82_in_air(self):
        F0, F82 = np.array([0.9, 0.75, 0.4]), np.array([0.8, 0.7, 0.5])
        # a is solved from F82 and the model evaluated back at MU_BAR: ~20
        # roundings (pow within 4 ulps) of condition <= |Schlick| / F82 <= 2:
        # 160 u64 = 1.8e-14 < 1e-12. At mu = 1 both terms vanish: F0 within
        # F64_FEW_OPS (tightened from approx's default rel=1e-6).
        assert lazanyi_adjusted(MU_BAR, 1.0, F0, F82) == pytest.approx(F82, rel=1e-12)
        assert lazanyi_adjusted(1.0, 1.0, F0, F82) == pytest.approx(F0, rel=F64_FEW_OPS)
        assert lazanyi_a(F0, F82).shape == (3,)

    def test_baseline_inputs_and_names(self):
        nk = library_material("Au")
        inputs = baseline_inputs(nk)
        # The same reference by another path: F64_RGB_BOUND (1.3e-13);
        # tightened from assert_allclose's default rtol=1e-7 (no derivation).
        np.testing.assert_allclose(inputs["F0_air"], reference_ACEScg(nk, 1.0, 1.0), rtol=0, atol=F64_RGB_BOUND)
        with pytest.raises(ValueError, match="`name` must be one of"):
            baseline_ACEScg("phong", nk, 0.5, 1.5)
        out = baseline_ACEScg("schlick_exact_F0", nk, np.array([1.0, 1.0]), np.array([1.0, 2.0]))
        np.testing.assert_allclose(out, reference_ACEScg(nk, 1.0, np.array([1.0, 2.0])), atol=1e-12)
        # (at mu = 1 Schlick is F0: the reference itself, within F64_RGB_BOUND
        # of itself and a few u64; 1e-12 is that with a 7x margin.)

    def test_all_at_once_equal_one_by_one(self):
        nk = library_material("Cu")
        mu, eta = np.meshgrid(np.linspace(0.0, 1.0, 9), np.linspace(1.0, 2.5, 5))
        every = baselines_ACEScg(nk, mu, eta)
        assert tuple(every) == BASELINES
        for name in BASELINES:
            np.testing.assert_array_equal(every[name], baseline_ACEScg(name, nk, mu, eta))
            assert every[name].shape == (5, 9, 3)
