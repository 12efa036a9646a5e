"""fitting.colour.reference: the spectral reference."""

import numpy as np
import pytest

from fitting.colour.reference import reference_ACEScg, spectral_grid
from fitting.optics.library import library_material
from fitting.optics.nk import SpectralNK

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


class TestReference:
    def test_shape_and_limits(self):
        nk = library_material("Au")
        mu = np.linspace(0, 1, 11)[None, :]
        eta = np.array([1.0, 1.5, 2.5])[:, None]
        R = reference_ACEScg(nk, mu, eta)
        assert R.shape == (3, 11, 3)
        np.testing.assert_allclose(R[:, 0], 1.0, atol=1e-12)  # grazing
        assert np.all(R[0, -1] > R[2, -1])  # a coating lowers F0

    def test_perfect_mirror_like_conductor_is_white(self):
        wl = np.array([300.0, 900.0])
        nk = SpectralNK(wl, [1e-6, 1e-6], [1e6, 1e6], name="mirror")
        np.testing.assert_allclose(reference_ACEScg(nk, 0.7, 1.8), 1.0, atol=1e-6)

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
        assert diff.max() < 2e-3
