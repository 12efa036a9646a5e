"""The numpy microfacet BRDF: GGX, Smith, the coat, VNDF sampling."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.shading.microfacet import (
    ROUGHNESS_MIN,
    alpha_g_from_roughness,
    ggx_D,
    microfacet_brdf,
    refract_into_coat,
    sample_visible_normal,
    smith_G1,
    smith_G2,
    smith_lambda,
    specular_brdf,
)

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

CR = ((0.37, 0.38, 0.39), (0.6, 0.55, 0.0), (4.8, 4.8, 5.0))


def _directions(theta, phi=0.0):
    theta = np.asarray(theta, dtype=np.float64)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi) + 0.0 * theta, np.cos(theta)], axis=-1)


class TestGGX:
    @pytest.mark.parametrize("roughness", [0.1, 0.4, 1.0])
    def test_projected_area_is_one(self, roughness):
        # Heitz 2014, Eq. 4: the integral of D(h) cos(theta_h) over the hemisphere is 1.
        alpha = alpha_g_from_roughness(roughness)
        t = np.linspace(0.0, np.pi / 2, 200001)
        h = _directions(t)
        integrand = ggx_D(h, alpha) * np.cos(t) * np.sin(t) * 2.0 * np.pi
        assert np.trapezoid(integrand, t) == pytest.approx(1.0, abs=1e-4)  # the
        # trapezoid rule's discretisation error (h^2 / 12 |f''|), not rounding

    def test_peak_value(self):
        alpha = 0.3
        assert ggx_D(np.array([0.0, 0.0, 1.0]), alpha) == pytest.approx(
            1.0 / (np.pi * alpha**2), rel=16 * 2.0**-53
        )  # a few
        # roundings; tightened from approx's default rel=1e-6

    def test_roughness_clamped(self):
        assert alpha_g_from_roughness(0.0) == ROUGHNESS_MIN**2
        assert alpha_g_from_roughness(3.0) == 1.0
        # A kernel never raises on numeric input: NaN propagates.
        assert np.isnan(alpha_g_from_roughness(np.nan))


class TestSmith:
    def test_lambda_published_limit(self):
        # Lambda = 0 at normal incidence; G1 -> 0 at grazing, finite.
        assert smith_lambda(1.0, 0.5) == 0.0
        assert 0.0 <= smith_G1(0.0, 0.5) < 1e-6  # G1 -> 0 at grazing: the
        # kernel's clamped cosine, a limit claim, not rounding

    def test_visible_area_identity(self):
        # Heitz 2014, Eq. 5: int G1(v, h) <v, h> D(h) dh = cos(theta_v).
        alpha, mu = 0.4, 0.6
        v = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
        t, p = np.meshgrid(np.linspace(0, np.pi / 2, 1201), np.linspace(0, 2 * np.pi, 1201), indexing="ij")
        h = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)
        integrand = smith_G1(mu, alpha) * np.maximum(h @ v, 0) * ggx_D(h, alpha) * np.sin(t)
        total = np.trapezoid(np.trapezoid(integrand, p[0], axis=1), t[:, 0])
        assert total == pytest.approx(mu, rel=2e-3)  # the 2-D trapezoid rule's
        # discretisation error near the peak of D, not rounding

    def test_G2_bounds_and_symmetry(self):
        mu = np.linspace(-0.2, 1.0, 50)
        G = smith_G2(mu[:, None], mu[None, :], 0.3)
        assert np.all((G >= 0) & (G <= 1))
        np.testing.assert_allclose(G, G.T, rtol=1e-15)  # 1 / (1 + L(a) + L(b)):
        # a sum of two terms in swapped order, <= 4 u64 = 4.4e-16
        assert np.all(G[mu <= 0] == 0)


class TestBRDF:
    def test_reciprocal(self):
        rng = np.random.default_rng(1)
        wo = _directions(rng.uniform(0, 1.5, 100), rng.uniform(0, 6, 100))
        wi = _directions(rng.uniform(0, 1.5, 100), rng.uniform(0, 6, 100))
        for mode in ("immersed", "coated"):
            f1 = microfacet_brdf(wo, wi, 0.4, *CR, mode=mode, eta_i=1.6, coat_roughness=0.2)
            f2 = microfacet_brdf(wi, wo, 0.4, *CR, mode=mode, eta_i=1.6, coat_roughness=0.2)
            np.testing.assert_allclose(f1, f2, rtol=1e-12)  # reciprocity:
            # the same terms in another order, ~100 roundings with the coat's
            # refraction of condition <= ~10: 1e3 u64 = 1.1e-13

    def test_coated_at_eta_1_is_immersed(self):
        rng = np.random.default_rng(2)
        wo = _directions(rng.uniform(0, 1.55, 500), rng.uniform(0, 6, 500))
        wi = _directions(rng.uniform(0, 1.55, 500), rng.uniform(0, 6, 500))
        for r, rc in ((0.05, 0.0), (0.5, 0.3), (1.0, 1.0)):
            coated = microfacet_brdf(wo, wi, r, *CR, mode="coated", eta_i=1.0, coat_roughness=rc)
            immersed = microfacet_brdf(wo, wi, r, *CR)
            np.testing.assert_allclose(coated, immersed, rtol=1e-12, atol=0)  # as
            # above: eta_i = 1 makes the coat's terms exact identities

    def test_below_horizon_is_zero_and_finite_everywhere(self):
        wo = _directions(np.linspace(0, np.pi, 40))
        wi = _directions(np.linspace(0, np.pi, 40), 2.0)
        for mode in ("immersed", "coated"):
            f = microfacet_brdf(wo[:, None], wi[None, :], 0.0, *CR, mode=mode, eta_i=2.5)
            assert np.all(np.isfinite(f))
            assert np.all(f[wo[:, 2] <= 0] == 0)

    def test_refraction_obeys_snell(self):
        w = _directions(np.linspace(0, np.pi / 2, 30), 0.7)
        t = refract_into_coat(w, 1.5)
        np.testing.assert_allclose(np.linalg.norm(t, axis=-1), 1.0, rtol=16 * 2.0**-53)  # Snell's
        # refraction keeps unit length to ~10 roundings (tightened from rtol=1e-7)
        np.testing.assert_allclose(np.hypot(t[:, 0], t[:, 1]) * 1.5, np.hypot(w[:, 0], w[:, 1]), rtol=16 * 2.0**-53)

    def test_bad_input(self):
        with pytest.raises(ValueError, match="`mode` must be one of immersed, coated"):
            microfacet_brdf([0, 0, 1], [0, 0, 1], 0.3, *CR, mode="layered")
        f = microfacet_brdf([0, 0, 1], [0, 0, 1], 0.3, *CR, mode="coated", eta_i=np.nan)
        assert np.all(np.isnan(f))


class TestVisibleNormalSampling:
    @pytest.mark.parametrize("roughness, mu", [(0.2, 0.9), (0.6, 0.3), (1.0, 0.05)])
    def test_albedo_matches_brute_force_quadrature(self, roughness, mu):
        alpha = alpha_g_from_roughness(roughness)
        v = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
        rng = np.random.default_rng(3)
        h = sample_visible_normal(v, alpha, rng.random(200000), rng.random(200000))
        l = 2 * (h @ v)[:, None] * h - v
        w = np.where(l[:, 2] > 0, smith_G2(mu, l[:, 2], alpha) / smith_G1(mu, alpha), 0.0)
        # Quadrature of f cos(theta_l) over the light hemisphere.
        t, p = np.meshgrid(np.linspace(0, np.pi / 2, 801), np.linspace(0, 2 * np.pi, 1601), indexing="ij")
        L = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)
        f = specular_brdf(np.broadcast_to(v, L.shape), L, alpha, lambda x: np.ones(x.shape + (1,)))[..., 0]
        E = np.trapezoid(np.trapezoid(f * np.cos(t) * np.sin(t), p[0], axis=1), t[:, 0])
        # Derived: 4 Monte Carlo standard errors of the 200000-sample mean plus
        # the 801 x 1601 trapezoid rule's discretisation error (2e-3).
        assert w.mean() == pytest.approx(E, abs=4 * w.std() / np.sqrt(w.size) + 2e-3)
