"""fitting.optics.fresnel: closed forms, limits, NaN policy."""

import numpy as np
import pytest

from fitting.colour.reference import reference_ACEScg
from fitting.optics.fresnel import fresnel_conductor, fresnel_conductor_derivatives, fresnel_dielectric
from fitting.optics.nk import SpectralNK
from precision import F64_FEW_OPS

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


class TestFresnelConductor:
    def test_normal_incidence_closed_form(self):
        # R(0) = ((n - eta_i)^2 + k^2) / ((n + eta_i)^2 + k^2)
        for n, k, eta in [(0.2, 3.5, 1.0), (1.5, 0.0, 1.0), (0.3, 2.4, 1.7), (2.9, 0.4, 2.5)]:
            expected = ((n - eta) ** 2 + k**2) / ((n + eta) ** 2 + k**2)
            assert fresnel_conductor(1.0, eta, n, k) == pytest.approx(expected, rel=1e-12)  # ~10 roundings; the
            # difference n - eta of condition <= (n + eta) / |n - eta| ~ 20 here: 200 u64 = 2e-14

    def test_grazing_is_one(self):
        # Grazing: the closed form is 1 to a few roundings (tightened from
        # approx's default rel=1e-6).
        assert fresnel_conductor(0.0, [1.0, 1.5, 2.5], 0.2, 3.0) == pytest.approx([1, 1, 1], rel=F64_FEW_OPS)

    def test_total_internal_reflection(self):
        n, eta_i = 1.33, 2.0
        critical = np.sqrt(1.0 - (n / eta_i) ** 2)
        mu = np.linspace(0.0, critical * 0.999, 50)
        # Total internal reflection: |r| = 1 is |a|^2 / |b|^2 of two complex
        # conjugates formed by the same operations, so only ~10 roundings of
        # values ~1 separate it from 1: 40 u64 = 4e-15 < 1e-12. Measured: 0.
        np.testing.assert_allclose(fresnel_conductor(mu, eta_i, n, 0.0), 1.0, atol=1e-12)
        assert fresnel_conductor(1.0, eta_i, n, 0.0) < 1.0

    def test_index_matched_is_zero_everywhere(self):
        mu = np.linspace(0.0, 1.0, 101)
        R = fresnel_conductor(mu, 1.5, 1.5, 0.0)
        # Index matched: the numerator's difference of two identically formed
        # values is exactly 0 on every CPU.
        np.testing.assert_allclose(R, 0.0, atol=1e-15)
        assert np.all(np.isfinite(R))

    def test_dielectric_formula_matches_k_zero(self):
        mu = np.linspace(0.0, 1.0, 201)
        for eta_i, n in [(1.0, 1.5), (1.5, 1.0), (2.0, 1.33), (1.2, 2.4)]:
            np.testing.assert_allclose(
                fresnel_conductor(mu, eta_i, n, 0.0),
                fresnel_dielectric(mu, eta_i, n),
                atol=1e-12,  # two closed forms of
                # ~20 operations, the critical-angle difference of condition
                # <= 1e2 on this grid: 2000 u64 = 2.2e-13
            )

    def test_n_dimensional_broadcast(self):
        mu = np.linspace(0, 1, 7)[:, None, None]
        eta = np.linspace(1, 2.5, 5)[None, :, None]
        n = np.linspace(0.2, 1.5, 3)
        R = fresnel_conductor(mu, eta, n, 2.0)
        assert R.shape == (7, 5, 3)
        # The same kernel on one element: same operations, another SIMD lane
        # (exp/pow may round by an ulp differently): F64_FEW_OPS.
        assert R[3, 2, 1] == pytest.approx(fresnel_conductor(mu[3, 0, 0], eta[0, 2, 0], n[1], 2.0), rel=F64_FEW_OPS)

    def test_never_nan_on_extremes(self):
        mu = np.array([-1.0, 0.0, 1e-300, 0.5, 1.0, 2.0])
        R = fresnel_conductor(mu, 1.0, 1e-9, 1e9)
        assert np.all(np.isfinite(R)) and np.all((R >= 0) & (R <= 1))

    def test_kernels_never_raise_and_clamp_to_the_physical_limit(self):
        # Finite but unphysical input: clamped, never raised, never NaN.
        mu = np.array([-1.0, 0.0, 0.3, 1.0, 2.0])
        for n, k, eta_i in [
            (0.0, 0.0, 1.0),
            (-2.0, -1.0, 1.5),
            (1e300, 1e300, 1.0),
            (1.5, 0.0, 0.0),
            (1e-300, 0.0, 1e300),
            (2.0, 3.0, -1.0),
        ]:
            R = fresnel_conductor(mu, eta_i, n, k)
            assert np.all(np.isfinite(R)) and np.all((R >= 0) & (R <= 1)), (n, k, eta_i)
        # A huge index is a perfect mirror; a negative k is clamped to k = 0.
        # Clamped to INDEX_LIMITS' 1e8: the physics gives 1 - R ~ 4 n mu /
        # (n^2 + k^2) = 1.4e-8 there (fitting/optics/fresnel.py: "past 1e8 the
        # reflectance is 1 to 1e-8"), not rounding; 1e-7 is that figure with
        # a 5x margin. Measured: 2.1e-8 (1.1e-16 with n = 0.2).
        assert fresnel_conductor(0.7, 1.0, 1e300, 1e300) == pytest.approx(1.0, abs=1e-7)
        assert fresnel_conductor(0.7, 1.2, 1.6, -5.0) == fresnel_conductor(0.7, 1.2, 1.6, 0.0)
        for eta_i, eta_t in [(0.0, 1.5), (1.5, -3.0), (1e300, 1.0), (1.0, 1e-300)]:
            R = fresnel_dielectric(mu, eta_i, eta_t)
            assert np.all(np.isfinite(R)) and np.all((R >= 0) & (R <= 1)), (eta_i, eta_t)

    def test_nan_in_gives_nan_out_where_it_is(self):
        R = fresnel_conductor([0.5, np.nan], 1.0, 0.2, 3.0)
        assert np.isfinite(R[0]) and np.isnan(R[1])
        assert np.isnan(fresnel_dielectric(0.5, 1.0, np.nan))
        # +/-inf is clamped like any large value.
        assert fresnel_conductor(0.5, 1.0, 0.2, np.inf) == pytest.approx(1.0, abs=1e-7)  # as above

    def test_non_numbers_refused(self):
        with pytest.raises(ValueError, match="`k` must be numbers"):
            fresnel_conductor(0.5, 1.0, 0.2, "gold")

    def test_the_boundaries_refuse_non_finite_data(self):
        # What the kernels would turn into NaN never reaches them: the data
        # types and the reference refuse it where it enters.
        with pytest.raises(ValueError, match="`k` must be finite, got inf at index 1"):
            SpectralNK([400.0, 500.0, 600.0], [0.2, 0.2, 0.2], [3.0, np.inf, 3.0], name="x")
        nk = SpectralNK([300.0, 900.0], [0.2, 0.2], [3.0, 3.0], name="flat")
        with pytest.raises(ValueError, match="`cos_theta` must be finite, got nan"):
            reference_ACEScg(nk, [0.5, np.nan], 1.0)
        with pytest.raises(ValueError, match="`eta_i` must be finite"):
            reference_ACEScg(nk, 0.5, np.nan)


class TestFresnelConductorDerivatives:
    @pytest.mark.parametrize("eta_i, n, k", [(1.0, 0.2, 3.5), (1.5, 1.1, 6.0), (2.5, 2.9, 0.3), (1.33, 0.05, 2.0)])
    def test_against_central_differences(self, eta_i, n, k):
        """The exact derivatives in n and k against central differences of fresnel_conductor (step 1e-6: error ~1e-10)."""
        mu = np.linspace(0.0, 1.0, 41)
        R, dn, dk = fresnel_conductor_derivatives(mu, eta_i, n, k)
        h = 1e-6
        np.testing.assert_array_equal(R, fresnel_conductor(mu, eta_i, n, k))
        fd_n = (fresnel_conductor(mu, eta_i, n + h, k) - fresnel_conductor(mu, eta_i, n - h, k)) / (2 * h)
        fd_k = (fresnel_conductor(mu, eta_i, n, k + h) - fresnel_conductor(mu, eta_i, n, k - h)) / (2 * h)
        np.testing.assert_allclose(dn, fd_n, atol=1e-8)
        np.testing.assert_allclose(dk, fd_k, atol=1e-8)

    def test_broadcast_and_clamps(self):
        """Per channel (S, 1) x (3,) shapes; an index clamped at its limit has no derivative; grazing (R = 1) none."""
        R, dn, dk = fresnel_conductor_derivatives(
            np.linspace(0.0, 1.0, 5)[:, None], 1.5, np.array([0.3, 0.6, 1.2]), np.array([3.0, -1.0, 2.0])
        )
        assert R.shape == dn.shape == dk.shape == (5, 3)
        assert np.all(dk[:, 1] == 0.0) and np.all(dn[0] == 0.0) and np.all(dk[0] == 0.0)
        assert np.all(np.isfinite(dn)) and np.all(np.isfinite(dk))
