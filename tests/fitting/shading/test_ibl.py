"""The split-sum LUT: pre-integration, lookup, file format, average Fresnel,
the directional albedo of any Fresnel function."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from fitting.models.baselines import lazanyi_adjusted, external_medium_F0, lazanyi_a
from fitting.models.coated_conductor import model_from_parameters
from fitting.shading.ibl import (
    _hammersley,
    _node_terms,
    average_fresnel,
    decode_lut,
    directional_albedo,
    encode_lut,
    energy_compensation,
    generate_lut,
    split_sum_lazanyi,
    split_sum_model,
    split_sum_schlick,
)

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)


@pytest.fixture(scope="module")
def lut():
    return generate_lut(shape=(16, 24, 32), samples=512)


class TestAverageFresnel:
    @pytest.mark.parametrize("F0, a, alpha", [(0.5, 1.2, 4.0), (0.9, -0.3, 0.9), (0.2, 3.0, 8.0), (1.0, 0.0, 6.0)])
    def test_closed_form_matches_quadrature(self, F0, a, alpha):
        value, _ = quad(lambda mu: 2.0 * mu * model_from_parameters(mu, F0, a, alpha), 0.0, 1.0, epsabs=1e-13)
        assert average_fresnel(F0, a, alpha) == pytest.approx(value, abs=1e-12)  # quad's
        # epsabs 1e-13 plus the closed form's ~20 roundings (Beta functions via
        # lgamma/exp, within 4 ulps each) of values <= 1: 80 u64 = 1e-14

    def test_n_dimensional(self):
        F0 = np.full((4, 3), 0.5)
        assert average_fresnel(F0, 1.0, 5.0).shape == (4, 3)

    def test_perfect_mirror_compensation(self):
        # F = 1 everywhere: average 1, and the factor restores the white lobe to 1.
        assert average_fresnel(1.0, 0.0, 6.0) == 1.0
        assert energy_compensation(0.8, 1.0) * 0.8 == pytest.approx(1.0, rel=8 * 2.0**-53)  # two
        # roundings (1 / 0.8, * 0.8); tightened from approx's default rel=1e-6


class TestLUT:
    def test_nodes_reproduced_exactly(self, lut):
        n_alpha, n_r, n_mu = lut.shape
        mu = (np.arange(n_mu) / (n_mu - 1)) ** 2
        r = np.arange(n_r) / (n_r - 1)
        alphas = lut.alpha_nodes()
        got = lut.lookup(mu[None, :], r[:, None], alphas[7])
        # At the nodes the bilinear weights are 1 and 0 up to the rounding of the
        # node coordinates (a few u64), so the float32 table value comes back
        # to ~1e-15: rtol 1e-6 (17 u32) only allows for a float32 weight.
        np.testing.assert_allclose(got, lut.data[7].astype(np.float64), rtol=1e-6, atol=1e-12)

    def test_deterministic(self):
        a = generate_lut(shape=(2, 3, 4), samples=64)
        b = generate_lut(shape=(2, 3, 4), samples=64)
        assert a.data.tobytes() == b.data.tobytes()

    def test_terms_are_physical(self, lut):
        A, B, G = lut.data[..., 0], lut.data[..., 1], lut.data[..., 2]
        assert np.all(A >= 0) and np.all(B >= 0) and np.all(G >= 0)
        assert np.all(A + B <= 1.0 + 1e-6)  # float32 table: 2 u32 of a sum <= 1, 1e-6 = 17 u32

    def test_split_sum_matches_direct_quadrature(self, lut):
        u1, u2 = _hammersley(8192)
        F0, a, alpha = np.array([0.6, 0.5, 0.4]), np.array([1.0, 0.7, 0.2]), np.array([5.0, 3.5, 2.0])
        mu = np.array([0.1, 0.37, 0.8])
        for r in (0.15, 0.55, 0.9):
            terms = _node_terms(mu, r, alpha, u1, u2)
            expected = F0 * terms[..., 0] + terms[..., 1] - a * terms[..., 2]
            got = split_sum_model(mu, r, F0, a, alpha, lut)
            # Not rounding: the LUT's interpolation between its (mu, r, alpha) nodes
            # and the quadrature's 64 against 8192 samples (Monte Carlo-like error
            # ~1/sqrt(64) of the integrand's spread); 1% is the LUT's accuracy claim.
            np.testing.assert_allclose(got, expected, rtol=0.01)

    def test_baselines_are_the_same_form(self, lut):
        F0_air, F82_air = np.array([0.95, 0.64, 0.29]), np.array([0.91, 0.70, 0.45])
        mu = np.linspace(0.05, 1, 7)
        lz = split_sum_lazanyi(mu, 0.4, 1.5, F0_air, F82_air, lut)
        ref = split_sum_model(mu, 0.4, external_medium_F0(F0_air, 1.5), lazanyi_a(F0_air, F82_air), 6.0, lut)
        # The same split sum with the same inputs formed another way
        # (external_medium_F0, lazanyi_a: ~200 u64 as in test_baselines):
        # within the default rtol=1e-7, 4e5 times that bound.
        np.testing.assert_allclose(lz, ref)
        sch = split_sum_schlick(mu, 0.4, F0_air, lut)
        np.testing.assert_allclose(sch, split_sum_model(mu, 0.4, F0_air, 0.0, 3.0, lut))  # as above
        # At roughness 0 the albedo is the Fresnel itself (up to shadowing at grazing).
        np.testing.assert_allclose(
            split_sum_lazanyi(0.8, 0.0, 1.5, F0_air, F82_air, lut),
            lazanyi_adjusted(0.8, 1.5, F0_air, F82_air),
            rtol=2e-3,  # not rounding: the
            # LUT's interpolation and the shadowing term at roughness 0 (a model claim)
        )

    def test_rejects_non_finite(self, lut):
        with pytest.raises(ValueError, match="`NdotV` must be finite"):
            split_sum_model(np.nan, 0.3, 0.5, 0.1, 5.0, lut)


class TestFileFormat:
    def test_round_trip(self, lut):
        blob = encode_lut(lut)
        back = decode_lut(blob)
        assert back.data.tobytes() == lut.data.tobytes() and back.alpha_range == lut.alpha_range
        assert len(blob) == 32 + 4 + lut.data.nbytes

    def test_damaged(self, lut):
        blob = bytearray(encode_lut(lut))
        blob[100] ^= 1
        with pytest.raises(ValueError, match="CRC-32 mismatch"):
            decode_lut(bytes(blob))
        with pytest.raises(ValueError, match="truncated"):
            decode_lut(b"CFIBLUT1")
        with pytest.raises(ValueError, match="not a split-sum LUT"):
            decode_lut(b"X" * 100)
        with pytest.raises(ValueError, match="must be"):
            decode_lut(bytes(blob[:-8]))

    def test_rejects_bad_shape(self):
        with pytest.raises(ValueError, match="`shape` must hold"):
            generate_lut(shape=(1, 4, 4))
        with pytest.raises(ValueError, match="`samples` must lie"):
            generate_lut(samples=3)


class TestDirectionalAlbedo:
    def test_model_fresnel_is_the_lut_terms(self):
        # The same quadrature as the LUT's nodes: E = F0 A + B - a G exactly.
        mu = np.array([0.0, 0.04, 0.3, 0.81, 1.0])
        F0, a, alpha = np.array([0.9, 0.6, 0.3]), np.array([0.5, 0.2, -0.1]), np.array([6.0, 3.0, 1.5])
        u1, u2 = _hammersley(256)
        got = directional_albedo(mu, 0.4, lambda c: model_from_parameters(c[..., None], F0, a, alpha), 256)
        for c in range(3):
            A, B, G = np.moveaxis(_node_terms(mu, 0.4, np.array([alpha[c]]), u1, u2)[:, 0], -1, 0)
            np.testing.assert_allclose(got[:, c], F0[c] * A + B - a[c] * G, rtol=1e-12, atol=1e-15)  # the same
            # terms summed in another order over 8192 samples: 8192 u64 = 9e-13 relative

    def test_white_lobe_loses_energy_only_when_rough(self):
        white = lambda c: np.ones(c.shape + (3,))  # noqa: E731
        # A smooth mirror, every sample weight 1: a mean of ones, exact up to the
        # sum's rounding (N u64); 1e-6 is the module's smooth-limit claim.
        np.testing.assert_allclose(directional_albedo([1.0, 0.5], 0.0, white), 1.0, atol=1e-6)
        rough = directional_albedo([1.0, 0.5, 0.1], 1.0, white)
        assert np.all((rough > 0.2) & (rough < 0.9))  # physics, not rounding

    def test_n_dimensional_input_is_flattened(self):
        got = directional_albedo(np.full((2, 3), 0.5), 0.3, lambda c: np.ones(c.shape + (3,)), 64)
        assert got.shape == (6, 3)

    @pytest.mark.parametrize(
        "NdotV, roughness, samples, message",
        [
            ([0.5, np.nan], 0.3, 64, "NdotV"),
            ([0.5], np.inf, 64, "roughness"),
            ([0.5], 0.3, 0, "samples"),
        ],
    )
    def test_refusals_name_the_argument(self, NdotV, roughness, samples, message):
        with pytest.raises(ValueError, match=message):
            directional_albedo(NdotV, roughness, lambda c: np.ones(c.shape + (3,)), samples)
