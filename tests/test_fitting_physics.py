"""Fresnel, colorimetry and reference: closed forms and colour-science."""

import numpy as np
import pytest

from fitting.colour.colorimetry import (
    ACES_WHITE_XY,
    ACEScg_to_Lab,
    ACEScg_to_Lab_jacobian,
    ACEScg_to_XYZ,
    spectral_to_ACEScg_weights,
)
from fitting.colour.delta_e import delta_E_2000
from fitting.colour.reference import reference_ACEScg, spectral_grid, spectral_weights
from fitting.optics.fresnel import fresnel_conductor, fresnel_dielectric
from fitting.optics.library import library_material
from fitting.optics.nk import SpectralNK


class TestFresnelConductor:
    def test_normal_incidence_closed_form(self):
        # R(0) = ((n - eta_i)^2 + k^2) / ((n + eta_i)^2 + k^2)
        for n, k, eta in [(0.2, 3.5, 1.0), (1.5, 0.0, 1.0), (0.3, 2.4, 1.7), (2.9, 0.4, 2.5)]:
            expected = ((n - eta) ** 2 + k**2) / ((n + eta) ** 2 + k**2)
            assert fresnel_conductor(1.0, eta, n, k) == pytest.approx(expected, rel=1e-12)

    def test_grazing_is_one(self):
        assert fresnel_conductor(0.0, [1.0, 1.5, 2.5], 0.2, 3.0) == pytest.approx([1, 1, 1])

    def test_total_internal_reflection(self):
        n, eta_i = 1.33, 2.0
        critical = np.sqrt(1.0 - (n / eta_i) ** 2)
        mu = np.linspace(0.0, critical * 0.999, 50)
        np.testing.assert_allclose(fresnel_conductor(mu, eta_i, n, 0.0), 1.0, atol=1e-12)
        assert fresnel_conductor(1.0, eta_i, n, 0.0) < 1.0

    def test_index_matched_is_zero_everywhere(self):
        mu = np.linspace(0.0, 1.0, 101)
        R = fresnel_conductor(mu, 1.5, 1.5, 0.0)
        np.testing.assert_allclose(R, 0.0, atol=1e-15)
        assert np.all(np.isfinite(R))

    def test_dielectric_formula_matches_k_zero(self):
        mu = np.linspace(0.0, 1.0, 201)
        for eta_i, n in [(1.0, 1.5), (1.5, 1.0), (2.0, 1.33), (1.2, 2.4)]:
            np.testing.assert_allclose(
                fresnel_conductor(mu, eta_i, n, 0.0), fresnel_dielectric(mu, eta_i, n), atol=1e-12
            )

    def test_n_dimensional_broadcast(self):
        mu = np.linspace(0, 1, 7)[:, None, None]
        eta = np.linspace(1, 2.5, 5)[None, :, None]
        n = np.linspace(0.2, 1.5, 3)
        R = fresnel_conductor(mu, eta, n, 2.0)
        assert R.shape == (7, 5, 3)
        assert R[3, 2, 1] == pytest.approx(fresnel_conductor(mu[3, 0, 0], eta[0, 2, 0], n[1], 2.0))

    def test_never_nan_on_extremes(self):
        mu = np.array([-1.0, 0.0, 1e-300, 0.5, 1.0, 2.0])
        R = fresnel_conductor(mu, 1.0, 1e-9, 1e9)
        assert np.all(np.isfinite(R)) and np.all((R >= 0) & (R <= 1))

    def test_non_finite_input_refused(self):
        with pytest.raises(ValueError, match="`cos_theta` must be finite, got nan"):
            fresnel_conductor([0.5, np.nan], 1.0, 0.2, 3.0)
        with pytest.raises(ValueError, match="`k` must be finite, got inf"):
            fresnel_conductor(0.5, 1.0, 0.2, np.inf)
        with pytest.raises(ValueError, match="`eta_t` must be finite"):
            fresnel_dielectric(0.5, 1.0, np.nan)


class TestColorimetry:
    def test_white_maps_to_one(self):
        nodes, W = spectral_weights(1.0)
        np.testing.assert_allclose(W @ np.ones(nodes.size), 1.0, atol=1e-12)
        nodes5, W5 = spectral_weights(5.0)
        np.testing.assert_allclose(W5 @ np.ones(nodes5.size), 1.0, atol=1e-12)

    def test_against_colour_sd_to_XYZ(self):
        import colour

        nodes = spectral_grid(1.0)
        reflectance = 0.2 + 0.6 * np.exp(-(((nodes - 600.0) / 60.0) ** 2))
        sd = colour.SpectralDistribution(dict(zip(nodes, reflectance)))
        cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
        illuminant = colour.sd_CIE_illuminant_D_series(ACES_WHITE_XY)
        XYZ = colour.sd_to_XYZ(sd, cmfs, illuminant, method="Integration") / 100.0
        # Same white on both sides: adapt colour's XYZ to ACEScg, normalise by white.
        W = spectral_weights(1.0)[1]
        white_XYZ = colour.sd_to_XYZ(
            colour.SpectralDistribution(dict(zip(nodes, np.ones_like(nodes)))),
            cmfs, illuminant, method="Integration",
        ) / 100.0
        RGB_colour = colour.XYZ_to_RGB(
            XYZ, colour.RGB_COLOURSPACES["ACEScg"], illuminant=colour.XYZ_to_xy(white_XYZ),
            chromatic_adaptation_transform="CAT02",
        )
        RGB_white = colour.XYZ_to_RGB(
            white_XYZ, colour.RGB_COLOURSPACES["ACEScg"], illuminant=colour.XYZ_to_xy(white_XYZ),
            chromatic_adaptation_transform="CAT02",
        )
        np.testing.assert_allclose(W @ reflectance, RGB_colour / RGB_white, rtol=2e-3)

    def test_coarse_weights_exact_for_linear_spectra(self):
        fine, W1 = spectral_weights(1.0)
        coarse, W10 = spectral_weights(10.0)
        line = lambda x: 0.1 + 0.8 * (x - 360.0) / 470.0  # noqa: E731
        np.testing.assert_allclose(W10 @ line(coarse), W1 @ line(fine), atol=1e-12)

    def test_weights_refuse_wrong_span(self):
        with pytest.raises(ValueError, match="must span 360-830"):
            spectral_to_ACEScg_weights(np.linspace(380, 780, 41))

    def test_lab_matches_colour(self):
        import colour

        rgb = np.array([[0.9, 0.6, 0.3], [1.0, 1.0, 1.0], [-0.01, 0.2, 0.1], [0.0, 0.0, 0.0]])
        expected = colour.XYZ_to_Lab(ACEScg_to_XYZ(rgb), ACES_WHITE_XY)
        np.testing.assert_allclose(ACEScg_to_Lab(rgb), expected, atol=1e-9)
        np.testing.assert_allclose(ACEScg_to_Lab([1.0, 1.0, 1.0]), [100.0, 0.0, 0.0], atol=1e-9)

    def test_lab_jacobian_matches_finite_differences(self):
        rng = np.random.default_rng(1)
        rgb = rng.uniform(0.02, 1.0, size=(20, 3))
        J = ACEScg_to_Lab_jacobian(rgb)
        h = 1e-7
        for j in range(3):
            step = np.zeros(3)
            step[j] = h
            numeric = (ACEScg_to_Lab(rgb + step) - ACEScg_to_Lab(rgb - step)) / (2 * h)
            np.testing.assert_allclose(J[:, :, j], numeric, rtol=1e-5, atol=1e-5)

    def test_delta_E_2000_published_pair(self):
        # Sharma, Wu & Dalal (2005), Table 1, pair 1: 2.0425.
        assert delta_E_2000([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485]) == pytest.approx(
            2.0425, abs=1e-4
        )


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
