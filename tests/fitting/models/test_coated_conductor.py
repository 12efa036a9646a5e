"""fitting.models.coated_conductor: Eq. 1 and 2, its Jacobian, the collapse."""

import numpy as np
import pytest

from fitting.domain import check_eta_i
from fitting.fits.curves_input import RGBCurve
from fitting.models.coated_conductor import (
    ALPHA_MIN,
    ModelAt,
    coated_conductor_model,
    collapse_to_eta_i,
    lean_constants,
    model_jacobian,
    model_parameters,
    normalised_eta_i,
)
from precision import F64_FEW_OPS, U64

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

KNOWN = np.array(
    [
        [[0.9, -0.1, 0.04], [0.75, -0.18, 0.1], [0.42, -0.2, 0.12]],
        [[0.3, -0.4, 0.2], [0.5, -0.8, 0.3], [0.6, -1.0, 0.4]],
        [[6.0, -1.0, 0.5], [5.0, 0.5, -0.2], [4.0, 1.0, 0.3]],
    ]
)


class TestModel:
    def test_eq1_at_known_points(self):
        F0, a, alpha = 0.5, 0.3, 4.0
        C = np.zeros((3, 3, 1))
        C[0], C[1], C[2] = F0, a, alpha
        mu = np.array([0.0, 0.25, 1.0])
        expected = F0 + (1 - F0) * (1 - mu) ** 5 - a * mu * (1 - mu) ** alpha
        # The same ~12 operations on [0, 1] (pow within 4 ulps): F64_FEW_OPS;
        # tightened from assert_allclose's default rtol=1e-7 (no derivation).
        np.testing.assert_allclose(coated_conductor_model(mu, 1.7, C)[:, 0], expected, rtol=0, atol=F64_FEW_OPS)

    def test_t_normalisation_and_clamp(self):
        # (1.75 - 1) / 1.5: two correctly rounded operations.
        assert normalised_eta_i(1.75, (1.0, 2.5)) == pytest.approx(0.5, rel=4 * U64)
        assert normalised_eta_i(0.5, (1.0, 2.5)) == 0.0
        assert normalised_eta_i(3.0, (1.0, 2.5)) == 1.0
        assert normalised_eta_i(1.7, (1.5, 1.5)) == 0.0
        np.testing.assert_array_equal(coated_conductor_model(0.3, 3.0, KNOWN), coated_conductor_model(0.3, 2.5, KNOWN))

    def test_alpha_is_clamped(self):
        C = KNOWN.copy()
        C[2] = -5.0
        F = coated_conductor_model(np.linspace(0, 1, 11), 1.5, C)
        assert np.all(np.isfinite(F))
        assert np.all(model_parameters(C, 1.5)[2] == ALPHA_MIN)

    def test_jacobian_matches_finite_differences(self):
        mu = np.linspace(0.0, 1.0, 13)
        eta = np.linspace(1.0, 2.5, 13)
        F, J = model_jacobian(mu, eta, KNOWN)
        h = 1e-7
        for p, c, j in [(0, 0, 0), (1, 1, 2), (2, 2, 1), (2, 0, 0)]:
            step = np.zeros_like(KNOWN)
            step[p, c, j] = h
            numeric = (
                coated_conductor_model(mu, eta, KNOWN + step) - coated_conductor_model(mu, eta, KNOWN - step)
            ) / (2 * h)
            # Central difference, h = 1e-7: rounding u64 |F| / h = 1.1e-9
            # (|F| <= ~1, coefficients up to 6) plus truncation h^2 |F'''| / 6
            # <= 1e-14 * 6^3: < 1e-8; 1e-6 is that with a 100x margin.
            np.testing.assert_allclose(J[:, c, p, j], numeric[:, c], atol=1e-6)

    def test_collapse_matches_general(self):
        collapsed = collapse_to_eta_i(KNOWN, 1.9)
        assert collapsed.shape == (3, 3, 1)
        mu = np.linspace(0, 1, 17)
        np.testing.assert_allclose(
            coated_conductor_model(mu, 1.9, collapsed),
            coated_conductor_model(mu, 1.9, KNOWN),
            atol=1e-14,  # the
            # polynomial in t summed before or after: ~3 roundings of terms
            # <= 6 (alpha's coefficients): 6 * 6 u64 = 4e-15 < 1e-14
        )

    def test_kernel_clamps_and_never_raises_on_numbers(self):
        # cos theta past [0, 1] and eta_i past the domain are clamped, +/-inf too.
        np.testing.assert_array_equal(
            coated_conductor_model([-1.0, 2.0], [0.5, np.inf], KNOWN),
            coated_conductor_model([0.0, 1.0], [1.0, 2.5], KNOWN),
        )
        # Finite coefficients however large never give NaN (inf - inf).
        huge = np.full((3, 3, 3), 1e300)
        huge[:, :, 1] = -1e300
        F = coated_conductor_model(np.linspace(0.0, 1.0, 11), 1.7, huge)
        assert np.all(np.isfinite(F))

    def test_model_at_fixed_samples_is_the_model(self):
        # One ModelAt, many coefficient arrays of every degree, in any order:
        # each is the model of those coefficients, to the bit (the solvers'
        # residuals rely on it).
        mu, eta = np.meshgrid(np.linspace(-0.1, 1.1, 13), np.linspace(0.9, 2.7, 5))
        at = ModelAt(mu, eta, (1.0, 2.5))
        for C in (KNOWN, KNOWN[:, :, :1], KNOWN * 1.3, KNOWN[:, :, :2], KNOWN - 0.2, KNOWN[:, :, :1] * 0.5):
            F = at(C)
            assert F.shape == mu.shape + (3,)
            assert np.array_equal(F, coated_conductor_model(mu, eta, C, (1.0, 2.5)))
            P = model_parameters(C, np.clip(eta, 1.0, 2.5), (1.0, 2.5))
            m = np.clip(mu, 0.0, 1.0)[..., None]
            expected = (
                P[..., 0, :] + (1.0 - P[..., 0, :]) * (1.0 - m) ** 5 - P[..., 1, :] * m * (1.0 - m) ** P[..., 2, :]
            )
            np.testing.assert_allclose(F, expected, rtol=0, atol=1e-14)  # a few roundings of terms <= 10
        assert ModelAt(0.3, 1.2, (1.0, 2.5))(KNOWN).shape == (3,)

    def test_nan_in_gives_nan_out_where_it_is(self):
        F = coated_conductor_model([0.2, np.nan], 1.5, KNOWN)
        assert np.all(np.isfinite(F[0])) and np.all(np.isnan(F[1]))
        assert np.all(np.isnan(coated_conductor_model(0.2, np.nan, KNOWN)))

    def test_non_numbers_refused(self):
        with pytest.raises(ValueError, match="`eta_i` must be numbers"):
            coated_conductor_model(0.2, "glass", KNOWN)

    def test_the_boundaries_refuse_non_finite_input(self):
        # What the model would turn into NaN is refused where it enters.
        with pytest.raises(ValueError, match="`eta_i` must lie in \\[1, 3\\], got nan"):
            check_eta_i(float("nan"))
        with pytest.raises(ValueError, match="`curve.eta_i` must lie in \\[1, 3\\], got inf"):
            RGBCurve(np.inf, np.linspace(0, 1, 5), np.full((5, 3), 0.5))
        with pytest.raises(ValueError, match="`curve.cos_theta\\[2\\]` must be finite"):
            RGBCurve(1.5, [0.0, 0.2, np.nan, 0.6, 1.0], np.full((5, 3), 0.5))

    def test_bad_coefficients(self):
        with pytest.raises(ValueError, match="`coefficients` must have shape"):
            collapse_to_eta_i(np.zeros((3, 3, 4)), 1.5)
        with pytest.raises(ValueError, match="finite"):
            collapse_to_eta_i(np.full((3, 3, 3), np.nan), 1.5)


class TestLeanConstants:
    """The lean shader's per-material constants (cf_coated_conductor_lean) are the same model."""

    def test_same_parameters_as_model_parameters(self):
        rng = np.random.default_rng(7)
        C = rng.uniform(-2.0, 5.0, (3, 3, 3))
        eta = np.linspace(0.8, 3.2, 41)  # outside the range too: t clamps
        P, (s, o) = lean_constants(C, (1.2, 2.4))
        t = np.clip(eta * s + o, 0.0, 1.0)[:, None]
        lean = P[:, 0][None] + t[..., None] * (P[:, 1][None] + t[..., None] * P[:, 2][None])
        lean[:, 2] = np.maximum(lean[:, 2], ALPHA_MIN)
        np.testing.assert_allclose(lean, model_parameters(C, eta, (1.2, 2.4)), rtol=0, atol=1e-12)

    def test_single_index_and_lower_degree(self):
        C = np.arange(18.0).reshape(3, 3, 2)
        P, t_map = lean_constants(C, (1.5, 1.5))
        assert t_map == (0.0, 0.0)
        np.testing.assert_array_equal(P[:, :2], np.swapaxes(C, 1, 2))
        assert np.all(P[:, 2] == 0.0)

    def test_rejects_bad_coefficients(self):
        with pytest.raises(ValueError, match="`coefficients` must have shape"):
            lean_constants(np.zeros((3, 3)))
