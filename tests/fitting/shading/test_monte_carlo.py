"""
Monte Carlo ground truth: the split sum agrees with it (the issue's Done-when
on a representative grid), white furnace, coated = immersed at eta_i = 1.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.fits.material import fit_material
from fitting.models.coated_conductor import model_parameters
from fitting.optics.library import library_material
from fitting.colour.reference import reference_ACEScg
from fitting.shading.ibl import default_lut, split_sum_model
from fitting.shading.microfacet import model_fresnel
from fitting.shading.monte_carlo import (
    directional_albedo,
    model_directional_albedo,
    rough_sphere_image,
    spectral_fresnel,
)

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

MIRROR = lambda VdotH: np.ones(np.shape(VdotH) + (1,))  # noqa: E731  (F = 1: a perfect mirror base)


@pytest.fixture(scope="module")
def fits():
    out = {}
    for name in ("Cr", "Au", "Al", "Hg"):
        packed = fit_material(library_material(name)).packed
        out[name] = model_parameters(
            packed.coefficients.astype(np.float64), np.array([1.0, 1.75, 2.5]), packed.eta_i_range
        )
    return out


class TestSplitSumAgainstMonteCarlo:
    """Immersed, white environment: within 1 % relative or 3 standard errors."""

    NDOTV = np.array([0.05, 0.15, 0.4, 0.7, 1.0])

    @pytest.mark.parametrize("roughness", [0.05, 0.3, 0.6, 1.0])
    def test_library_grid(self, fits, roughness):
        P = np.concatenate(list(fits.values()))  # (materials x eta_i, 3, 3)
        mc = model_directional_albedo(self.NDOTV, roughness, P, samples=16384, seed=11)
        lut = default_lut()
        for m, p in enumerate(P):
            split = split_sum_model(self.NDOTV, roughness, *p, lut)
            error = np.abs(split - mc.mean[m])
            ok = (error <= 0.01 * np.abs(mc.mean[m])) | (error <= 3.0 * mc.stderr[m])
            assert ok.all(), (m, roughness, error / mc.mean[m])

    def test_batch_equals_single(self, fits):
        p = fits["Cr"][1]
        batch = model_directional_albedo([0.3, 0.9], 0.4, p[None], samples=2048, seed=5)
        single = directional_albedo([0.3, 0.9], 0.4, model_fresnel(*p), samples=2048, seed=5)
        # The same samples (seed 5) summed by another path: 2048 u64 = 2.3e-13
        # relative for the mean; the standard error is a difference of sums
        # of squares (condition mean^2 / var <= ~1e3 here): 1e3 x that = 2.3e-10.
        np.testing.assert_allclose(batch.mean[0], single.mean, rtol=1e-12)
        np.testing.assert_allclose(batch.stderr[0], single.stderr, rtol=1e-9)


class TestWhiteFurnace:
    @pytest.mark.parametrize("roughness", [0.0, 0.1, 0.3, 0.5, 0.8, 1.0])
    @pytest.mark.parametrize(
        "mode, eta_i, coat_roughness",
        [
            ("immersed", 1.0, 0.0),
            ("coated", 1.0, 0.0),
            ("coated", 1.5, 0.0),
            ("coated", 1.5, 0.5),
            ("coated", 2.5, 0.2),
            ("coated", 3.0, 1.0),
        ],
    )
    def test_reflects_no_more_than_it_receives(self, roughness, mode, eta_i, coat_roughness):
        mu = np.array([0.02, 0.1, 0.3, 0.6, 1.0])
        E = directional_albedo(mu, roughness, MIRROR, mode, eta_i, coat_roughness, samples=8192, seed=2)
        assert np.all(E.mean <= 1.0 + 3.0 * E.stderr + 1e-12)
        assert np.all(E.mean > 0.0)

    def test_smooth_mirror_reflects_everything(self):
        E = directional_albedo([0.5, 1.0], 0.0, MIRROR, samples=1024)
        np.testing.assert_allclose(E.mean, 1.0, atol=1e-6)  # a mean of ones:
        # 1024 u64 = 1e-13; 1e-6 is the smooth-limit claim


class TestCoatedAtEtaOne:
    def test_same_estimate_as_immersed(self, fits):
        p = fits["Au"][0]
        mu = [0.1, 0.5, 0.9]
        a = directional_albedo(mu, 0.4, model_fresnel(*p), "coated", 1.0, 0.3, samples=16384, seed=1)
        b = directional_albedo(mu, 0.4, model_fresnel(*p), samples=16384, seed=3)
        assert np.all(np.abs(a.mean - b.mean) <= 4.0 * np.hypot(a.stderr, b.stderr))


class TestSpectral:
    def test_table_matches_direct_reference(self):
        nk = library_material("Cr")
        F = spectral_fresnel(nk, 1.5)
        mu = np.array([0.0, 0.013, 0.31, 0.777, 1.0])
        # The 4097-node linear table (fitting/shading/monte_carlo.py: error
        # < 1e-6, h^2 / 8 |F''|) plus the same margin again near grazing; an
        # interpolation bound, not rounding.
        np.testing.assert_allclose(F(mu), reference_ACEScg(nk, mu, 1.5), atol=2e-6)

    def test_smooth_limit_is_the_reference(self):
        nk = library_material("Au")
        E = directional_albedo([0.6], 0.0, spectral_fresnel(nk, 1.2), samples=256)
        # Smooth: every sample sees mu = 0.6, so only the table's 1e-6 remains;
        # 1e-4 is that with a wide margin (an interpolation bound).
        np.testing.assert_allclose(E.mean[0], reference_ACEScg(nk, 0.6, 1.2), rtol=1e-4)


class TestInputs:
    def test_refusals(self):
        with pytest.raises(ValueError, match="`samples` must lie in"):
            directional_albedo([0.5], 0.3, MIRROR, samples=3)
        with pytest.raises(ValueError, match="`mode` must be one of"):
            directional_albedo([0.5], 0.3, MIRROR, mode="layer")
        with pytest.raises(ValueError, match="`NdotV` must be finite"):
            directional_albedo([np.nan], 0.3, MIRROR)
        with pytest.raises(ValueError, match="`masking` must be one of"):
            directional_albedo([0.5], 0.3, MIRROR, masking="v-cavity")

    def test_sphere_image(self):
        image, mask = rough_sphere_image(16, 0.5, MIRROR, samples=256, NdotV_bins=16)
        assert image.shape == (16, 16, 1) and mask.sum() > 150
        assert np.all(image[~mask] == 0) and np.all((image[mask] > 0.3) & (image[mask] <= 1.0 + 1e-9))
