"""fitting.colour.reference: the spectral reference."""

import numpy as np
import pytest

from fitting.colour.reference import reference_ACEScg, spectral_grid
from fitting.optics.library import library_material
from fitting.optics.nk import SpectralNK

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

U64 = 2.0**-53  # float64 unit roundoff
# Where every node's reflectance is exactly 1 (grazing) or 1 to within
# ~100 u64 (a perfect mirror: 1 - R <= 4 n eta_i mu / |N|^2 = 7e-18 at
# |N| = 1e6), only the 471-node weight sum rounds: L u64 sum|w| = 471 *
# 1.1e-16 * 1.147 = 6e-14 (numpy's SIMD and BLAS choose the order). 1e-12
# is that with a 16x margin. Measured: 2.2e-16 (grazing), 5.6e-16 (mirror).
UNIT_REFLECTANCE_BOUND = 1e-12


class TestReference:
    def test_shape_and_limits(self):
        nk = library_material("Au")
        mu = np.linspace(0, 1, 11)[None, :]
        eta = np.array([1.0, 1.5, 2.5])[:, None]
        R = reference_ACEScg(nk, mu, eta)
        assert R.shape == (3, 11, 3)
        np.testing.assert_allclose(R[:, 0], 1.0, atol=UNIT_REFLECTANCE_BOUND)  # grazing
        assert np.all(R[0, -1] > R[2, -1])  # a coating lowers F0

    def test_perfect_mirror_like_conductor_is_white(self):
        wl = np.array([300.0, 900.0])
        # k at the largest accepted value (fitting.optics.nk.MAX_NK, 1000) and n
        # near 0: the physics puts R within 4 n eta / k^2 = 7e-15 of 1 and the
        # arithmetic within UNIT_REFLECTANCE_BOUND.
        nk = SpectralNK(wl, [1e-9, 1e-9], [1e3, 1e3], name="mirror")
        np.testing.assert_allclose(reference_ACEScg(nk, 0.7, 1.8), 1.0, atol=UNIT_REFLECTANCE_BOUND)

    def test_refuses_eta_below_one(self):
        with pytest.raises(ValueError, match="eta_i"):
            reference_ACEScg(library_material("Au"), 0.5, 0.9)

    def test_step_must_be_sane(self):
        with pytest.raises(ValueError, match="step_nm"):
            spectral_grid(0.0)
        with pytest.raises(ValueError, match="step_nm"):
            spectral_grid(np.nan)

    def test_coarse_step_close_to_1nm(self):
        nk = library_material("Cu")
        mu = np.linspace(0, 1, 9)
        diff = np.abs(reference_ACEScg(nk, mu, 1.5, 5.0) - reference_ACEScg(nk, mu, 1.5, 1.0))
        # Not a rounding bound: the 5 nm quadrature's discretisation error
        # (a modelling figure; measured 1.3e-4 on Cu). Rounding moves either
        # side by at most 1e-13 (F64_RGB_BOUND in test_reference_grid) on any CPU.
        assert diff.max() < 2e-3
