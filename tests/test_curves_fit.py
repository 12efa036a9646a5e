"""Tests of :mod:`fitting.fits.curves`: curves, bases, blending and fits from curves."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import reference_ACEScg
from fitting.fits.curves import CurveFitSettings, fit_curves
from fitting.fits.curves_base import (
    blend_weights,
    curve_base_from_coefficients,
    curve_base_from_nk,
    edited_target,
)
from fitting.fits.curves_input import CURVE_MIN_SAMPLES, RGBCurve, check_curves
from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import decode_pack, encode_pack
from fitting.optics.library import library_material

ANGLE = np.linspace(0.0, 90.0, 46)
MU = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))

# A gold-like model, quadratic in t (layout [parameter, channel, power]).
KNOWN = np.array([
    [[0.90, -0.08, 0.03], [0.74, -0.17, 0.10], [0.42, -0.36, 0.22]],
    [[0.20, 0.05, 0.00], [0.15, 0.03, 0.01], [0.10, 0.02, 0.00]],
    [[6.00, 1.00, 0.00], [5.00, 0.50, 0.00], [4.00, 0.50, 0.00]],
])


@pytest.fixture(scope="module")
def gold_base():
    return curve_base_from_nk(library_material("Au"))


def curve_of(coefficients, eta_i, eta_i_range=(1.0, 2.5)):
    return RGBCurve(eta_i, MU, coated_conductor_model(MU, eta_i, coefficients, eta_i_range))


class TestRGBCurve:
    def test_sorted_and_read_only(self):
        curve = RGBCurve(1.5, MU, np.full((MU.size, 3), 0.5))
        assert np.all(np.diff(curve.cos_theta) > 0)
        assert not curve.cos_theta.flags.writeable and not curve.rgb.flags.writeable

    def test_from_angles_matches_cos_theta(self):
        rgb = np.linspace(0.2, 1.0, ANGLE.size)[:, None].repeat(3, axis=1)
        a = RGBCurve.from_angles(1.5, ANGLE, rgb)
        b = RGBCurve(1.5, MU, rgb)
        np.testing.assert_allclose(a.cos_theta, b.cos_theta, atol=1e-15)
        np.testing.assert_array_equal(a.rgb, b.rgb)
        assert a.cos_theta[0] == 0.0  # 90 degrees is exactly grazing

    def test_above_one_names_the_place(self):
        rgb = np.full((MU.size, 3), 0.5)
        rgb[12, 0] = 1.2
        with pytest.raises(ValueError, match=r"`curve\.rgb\[\d+\]\[0\]` \(R at cos_theta .*\) must lie in \[0, 1\], got 1\.2"):
            RGBCurve(1.5, MU, rgb)

    def test_below_zero_names_the_place(self):
        rgb = np.full((MU.size, 3), 0.5)
        rgb[3, 2] = -0.01
        with pytest.raises(ValueError, match=r"\(B at cos_theta .*must lie in \[0, 1\], got -0\.01"):
            RGBCurve(1.5, MU, rgb)

    def test_rounding_above_one_is_clipped(self):
        rgb = np.full((MU.size, 3), 0.5)
        rgb[0] = 1.0 + 2e-10
        assert RGBCurve(1.5, MU, rgb).rgb.max() == 1.0

    @pytest.mark.parametrize("bad", [np.nan, np.inf])
    def test_non_finite(self, bad):
        rgb = np.full((MU.size, 3), 0.5)
        rgb[4, 1] = bad
        with pytest.raises(ValueError, match=r"G at .*must be finite"):
            RGBCurve(1.5, MU, rgb)
        mu = MU.copy()
        mu[2] = bad
        with pytest.raises(ValueError, match=r"`curve\.cos_theta\[2\]` must be finite"):
            RGBCurve(1.5, mu, np.full((MU.size, 3), 0.5))

    def test_too_few_samples(self):
        n = CURVE_MIN_SAMPLES - 1
        with pytest.raises(ValueError, match=rf"must hold {CURVE_MIN_SAMPLES} to .* got {n}"):
            RGBCurve(1.5, MU[:n], np.full((n, 3), 0.5))

    @pytest.mark.parametrize(
        "eta_i, mu, rgb, needle",
        [
            (0.9, MU, np.full((46, 3), 0.5), r"`curve\.eta_i` must lie in \[1, 3\], got 0\.9"),
            (1.5, np.append(MU[:-1], 1.5), np.full((46, 3), 0.5), r"cos_theta\[45\]` must lie in \[0, 1\], got 1\.5"),
            (1.5, MU, np.full((45, 3), 0.5), r"one \[R, G, B\] per cos_theta sample"),
            (1.5, np.append(MU[:-1], MU[0]), np.full((46, 3), 0.5), r"must not repeat a value"),
        ],
    )
    def test_rules(self, eta_i, mu, rgb, needle):
        with pytest.raises(ValueError, match=needle):
            RGBCurve(eta_i, mu, rgb)

    def test_angle_out_of_range(self):
        with pytest.raises(ValueError, match=r"`curve\.angle_deg\[1\]` must lie in \[0, 90\], got 95"):
            RGBCurve.from_angles(1.5, [0, 95, 30, 40, 50], np.full((5, 3), 0.5))


class TestCheckCurves:
    def test_mappings_named_by_index(self):
        good = {"eta_i": 1.2, "cos_theta": MU, "rgb": np.full((46, 3), 0.5)}
        bad = {"eta_i": 1.8, "angle_deg": ANGLE, "rgb": np.full((46, 3), 1.5)}
        with pytest.raises(ValueError, match=r"`curves\[1\]\.rgb\[0\]\[0\]`"):
            check_curves([good, bad])

    def test_one_of_cos_theta_or_angle(self):
        both = {"eta_i": 1.2, "cos_theta": MU, "angle_deg": ANGLE, "rgb": np.full((46, 3), 0.5)}
        with pytest.raises(ValueError, match=r"exactly one of `cos_theta` or `angle_deg`"):
            check_curves([both])

    def test_same_eta_twice(self):
        curve = {"eta_i": 1.2, "cos_theta": MU, "rgb": np.full((46, 3), 0.5)}
        with pytest.raises(ValueError, match=r"`curves\[1\]\.eta_i` must differ from `curves\[0\]\.eta_i`"):
            check_curves([curve, curve])

    @pytest.mark.parametrize("curves", [[], "curves", {"eta_i": 1.0}])
    def test_not_a_list_of_curves(self, curves):
        with pytest.raises(ValueError, match=r"`curves` must"):
            check_curves(curves)


class TestBlendWeights:
    def test_one_at_each_edit(self):
        edits = [2.2, 1.3, 1.7]
        W = blend_weights(np.array(edits), edits, 0.4)
        np.testing.assert_allclose(W, np.eye(3), atol=0)

    def test_partition_between_edits_and_fade_outside(self):
        eta = np.linspace(1.0, 2.5, 301)
        W = blend_weights(eta, [1.4, 2.0], 0.3)
        inside = (eta >= 1.4) & (eta <= 2.0)
        np.testing.assert_allclose(W[inside].sum(axis=1), 1.0, atol=1e-12)
        assert np.all(W[eta < 1.0999] == 0.0) and np.all(W[eta > 2.3001] == 0.0)
        assert np.all((W >= 0.0) & (W <= 1.0))

    def test_smooth(self):
        eta = np.linspace(1.0, 2.5, 3001)
        W = blend_weights(eta, [1.5, 1.9], 0.5)
        slope = np.diff(W, axis=0) / np.diff(eta)[:, None]
        # C1: the derivative has no jumps (finite-difference steps stay small).
        assert np.abs(np.diff(slope, axis=0)).max() < 0.05

    def test_width_rule(self):
        with pytest.raises(ValueError, match=r"`blend_width` must be a finite number > 0, got 0"):
            blend_weights([1.5], [1.5], 0)


class TestCurveBase:
    def test_interpolation_matches_reference(self, gold_base):
        rng = np.random.default_rng(1)
        mu, eta = rng.uniform(0, 1, 200), rng.uniform(1.0, 2.5, 200)
        exact = reference_ACEScg(library_material("Au"), mu, eta, 5.0)
        np.testing.assert_allclose(gold_base.rgb(mu, eta), exact, atol=2e-4)

    def test_cached_per_material(self, gold_base):
        assert curve_base_from_nk(library_material("Au")) is gold_base
        assert curve_base_from_nk(library_material("Au"), (1.2, 2.0)) is not gold_base

    def test_model_base_is_the_model(self):
        base = curve_base_from_coefficients(KNOWN, (1.0, 2.5))
        eta = np.array([1.0, 1.33, 2.5])
        np.testing.assert_allclose(
            base.rgb(MU[None, :], eta[:, None]), coated_conductor_model(MU[None, :], eta[:, None], KNOWN),
            atol=2e-4,
        )

    def test_single_eta_domain(self):
        base = curve_base_from_coefficients(KNOWN, (1.5, 1.5))
        np.testing.assert_allclose(base.rgb(MU, 1.5), coated_conductor_model(MU, 1.5, KNOWN, (1.5, 1.5)), atol=2e-4)


class TestEditedTarget:
    def test_curve_replaces_base_at_its_eta_and_fades(self, gold_base):
        edit = gold_base.rgb(MU, 1.5)
        edit[:, 0] = np.clip(edit[:, 0] + 0.1 * np.exp(-((ANGLE - 60) / 12) ** 2), 0, 1)
        curve = RGBCurve(1.5, MU, edit)
        np.testing.assert_allclose(edited_target(gold_base, [curve], MU, 1.5, 0.3), edit, atol=1e-12)
        far = edited_target(gold_base, [curve], MU, 2.2, 0.3)
        np.testing.assert_allclose(far, gold_base.rgb(MU, 2.2), atol=1e-12)
        halfway = edited_target(gold_base, [curve], MU, 1.65, 0.3)
        change = halfway[:, 0] - gold_base.rgb(MU, 1.65)[:, 0]
        assert 0.04 < change.max() < 0.06  # smoothstep(0.5) = 0.5 of the 0.1 bump
        np.testing.assert_allclose(halfway[:, 1:], gold_base.rgb(MU, 1.65)[:, 1:], atol=1e-12)

    def test_n_dimensional(self, gold_base):
        curve = RGBCurve(1.5, MU, gold_base.rgb(MU, 1.5))
        M, E = np.meshgrid(MU, np.linspace(1, 2.5, 7), indexing="xy")
        assert edited_target(gold_base, [curve], M, E).shape == M.shape + (3,)


class TestFitCurves:
    def test_one_curve_constant_in_eta(self):
        result = fit_curves([curve_of(KNOWN, 1.5)], name="one")
        assert result.degree == 0 and result.coefficients_float16.shape == (3, 3, 1)
        assert result.packed.degree == 0 and result.packed.eta_i_range == (1.0, 2.5)
        assert result.metrics["delta_E_mean"] < 0.1 and result.metrics["base"] is None

    @pytest.mark.parametrize("etas, degree", [((1.2, 2.2), 1), ((1.0, 1.7, 2.5), 2), ((1.0, 1.4, 1.9, 2.5), 2)])
    def test_degree_follows_the_curves(self, etas, degree):
        result = fit_curves([curve_of(KNOWN, e) for e in etas])
        assert result.degree == degree
        assert [c["eta_i"] for c in result.metrics["by_curve"]] == list(etas)
        assert result.metrics["delta_E_mean"] < 0.3

    def test_three_curves_recover_the_model(self):
        etas = (1.0, 1.75, 2.5)
        result = fit_curves([curve_of(KNOWN, e) for e in etas], max_nfev=200)
        eta = np.linspace(1.0, 2.5, 16)[:, None]
        dE = delta_E_map(coated_conductor_model(MU, eta, KNOWN), coated_conductor_model(MU, eta, result.coefficients_float16))
        assert dE.mean() < 0.2

    def test_unedited_base_reproduces_the_material(self, gold_base):
        result = fit_curves([RGBCurve(1.5, MU, gold_base.rgb(MU, 1.5))], base=gold_base, name="Au copy")
        assert result.degree == 2
        assert result.metrics["delta_E_mean"] < 0.3 and result.metrics["target"]["delta_E_mean"] < 0.4
        assert "Au with RGB curves edited at eta_i 1.5" in result.packed.source

    def test_edit_moves_the_fit(self, gold_base):
        plain = fit_curves([RGBCurve(1.5, MU, gold_base.rgb(MU, 1.5))], base=gold_base)
        edit = gold_base.rgb(MU, 1.5)
        edit[:, 0] *= 0.8  # a less red gold, kept inside [0, 1]
        edit[-1] = 1.0  # the model meets 1 at grazing (90 degrees)
        edited = fit_curves([RGBCurve(1.5, MU, edit)], base=gold_base)
        red_plain = coated_conductor_model(MU, 1.5, plain.coefficients_float16)[:, 0]
        red_edit = coated_conductor_model(MU, 1.5, edited.coefficients_float16)[:, 0]
        assert np.mean(np.abs(red_edit - edit[:, 0])) < 0.25 * np.mean(np.abs(red_plain - edit[:, 0]))
        # Far from the edit the material stays close to what it was (blend width 1).
        green_far = coated_conductor_model(MU, 2.5, edited.coefficients_float16)[:, 1]
        np.testing.assert_allclose(green_far, gold_base.rgb(MU, 2.5)[:, 1], atol=0.05)

    def test_packed_round_trip(self):
        result = fit_curves([curve_of(KNOWN, e) for e in (1.2, 2.2)], name="two")
        (decoded,) = decode_pack(encode_pack([result.packed]))
        np.testing.assert_array_equal(decoded.coefficients, result.coefficients_float16)
        assert decoded.name == "two" and decoded.degree == 1

    def test_timings_and_settings(self):
        result = fit_curves([curve_of(KNOWN, 1.5)])
        assert set(result.timings) >= {"target", "fit", "quantise", "total"}
        with pytest.raises(ValueError, match=r"`objective` must be one of"):
            fit_curves([curve_of(KNOWN, 1.5)], objective="l2")
        with pytest.raises(ValueError, match=r"`mu_samples` must be an integer in \[4, 256\]"):
            CurveFitSettings(mu_samples=2)

    def test_curve_outside_domain(self):
        with pytest.raises(ValueError, match=r"`curves\[0\]\.eta_i` must lie in the domain \[1\.2, 2\], got 2\.2"):
            fit_curves([curve_of(KNOWN, 2.2)], eta_i_range=(1.2, 2.0))

    def test_domain_must_be_the_bases(self, gold_base):
        with pytest.raises(ValueError, match=r"`eta_i_range` must be the base's domain \[1, 2\.5\]"):
            fit_curves([curve_of(KNOWN, 1.5)], base=gold_base, eta_i_range=(1.0, 2.0))

    def test_name_rule(self):
        with pytest.raises(ValueError, match=r"`name` must be a non-empty string"):
            fit_curves([curve_of(KNOWN, 1.5)], name=" ")
