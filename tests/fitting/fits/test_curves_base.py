"""fitting.fits.curves_base: bases and the blending of edits."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.colour.reference import reference_ACEScg
from fitting.fits.curves_base import (
    blend_weights,
    curve_base_from_coefficients,
    curve_base_from_nk,
    edited_target,
)
from fitting.fits.curves_input import RGBCurve
from fitting.models.coated_conductor import coated_conductor_model
from fitting.optics.library import library_material

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

# The curve base is a bilinear table (fitting/fits/curves_base.py: 257
# samples in cos theta, eta_i every 0.05): its error is the interpolation's,
# h^2 / 8 |F''| with h = 1/256 and |F''| up to ~100 near grazing for these
# conductors (1.9e-6 * 100 = 1.9e-4), plus < 1e-5 in eta_i; a discretisation
# bound, not rounding (rounding adds ~1e-13). Measured: 1.2e-4 (Au, 200 random
# points), 6.0e-5 (the model).
BASE_INTERPOLATION_BOUND = 2e-4
# The blend weights are (1 - s, s) of one smoothstep s: their sum rounds once
# or twice, 2 u64; 1e-12 and the exact-copy checks below (edited_target at an
# edit: w = 1 and 0 exactly, so 1e-12 only absorbs the blend's few roundings
# of values <= 1, ~4 u64).
BLEND_ROUNDING = 1e-12

ANGLE = np.linspace(0.0, 90.0, 46)

MU = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))

# A gold-like model, quadratic in t (layout [parameter, channel, power]).
KNOWN = np.array(
    [
        [[0.90, -0.08, 0.03], [0.74, -0.17, 0.10], [0.42, -0.36, 0.22]],
        [[0.20, 0.05, 0.00], [0.15, 0.03, 0.01], [0.10, 0.02, 0.00]],
        [[6.00, 1.00, 0.00], [5.00, 0.50, 0.00], [4.00, 0.50, 0.00]],
    ]
)


@pytest.fixture(scope="module")
def gold_base():
    return curve_base_from_nk(library_material("Au"))


class TestBlendWeights:
    def test_one_at_each_edit(self):
        edits = [2.2, 1.3, 1.7]
        W = blend_weights(np.array(edits), edits, 0.4)
        np.testing.assert_allclose(W, np.eye(3), atol=0)

    def test_partition_between_edits_and_fade_outside(self):
        eta = np.linspace(1.0, 2.5, 301)
        W = blend_weights(eta, [1.4, 2.0], 0.3)
        inside = (eta >= 1.4) & (eta <= 2.0)
        np.testing.assert_allclose(W[inside].sum(axis=1), 1.0, atol=BLEND_ROUNDING)
        assert np.all(W[eta < 1.0999] == 0.0) and np.all(W[eta > 2.3001] == 0.0)
        assert np.all((W >= 0.0) & (W <= 1.0))

    def test_smooth(self):
        eta = np.linspace(1.0, 2.5, 3001)
        W = blend_weights(eta, [1.5, 1.9], 0.5)
        slope = np.diff(W, axis=0) / np.diff(eta)[:, None]
        # C1: the derivative has no jumps (finite-difference steps stay small).
        # Not rounding: a C1 blend's slope changes by |W''| h <= 6 / 0.4^2 *
        # 5e-4 = 0.019 per step; a C0 kink would jump by ~1 / 0.4 = 2.5. 0.05
        # separates the two (measured 0.037 on a coarser grid, 1501 points).
        assert np.abs(np.diff(slope, axis=0)).max() < 0.05

    def test_width_rule(self):
        with pytest.raises(ValueError, match=r"`blend_width` must be a finite number > 0, got 0"):
            blend_weights([1.5], [1.5], 0)


class TestCurveBase:
    def test_interpolation_matches_reference(self, gold_base):
        rng = np.random.default_rng(1)
        mu, eta = rng.uniform(0, 1, 200), rng.uniform(1.0, 2.5, 200)
        exact = reference_ACEScg(library_material("Au"), mu, eta, 5.0)
        np.testing.assert_allclose(gold_base.rgb(mu, eta), exact, atol=BASE_INTERPOLATION_BOUND)

    def test_cached_per_material(self, gold_base):
        assert curve_base_from_nk(library_material("Au")) is gold_base
        assert curve_base_from_nk(library_material("Au"), (1.2, 2.0)) is not gold_base

    def test_model_base_is_the_model(self):
        base = curve_base_from_coefficients(KNOWN, (1.0, 2.5))
        eta = np.array([1.0, 1.33, 2.5])
        np.testing.assert_allclose(
            base.rgb(MU[None, :], eta[:, None]),
            coated_conductor_model(MU[None, :], eta[:, None], KNOWN),
            atol=BASE_INTERPOLATION_BOUND,
        )

    def test_single_eta_domain(self):
        base = curve_base_from_coefficients(KNOWN, (1.5, 1.5))
        np.testing.assert_allclose(
            base.rgb(MU, 1.5), coated_conductor_model(MU, 1.5, KNOWN, (1.5, 1.5)), atol=BASE_INTERPOLATION_BOUND
        )


class TestEditedTarget:
    def test_curve_replaces_base_at_its_eta_and_fades(self, gold_base):
        edit = gold_base.rgb(MU, 1.5)
        edit[:, 0] = np.clip(edit[:, 0] + 0.1 * np.exp(-(((ANGLE - 60) / 12) ** 2)), 0, 1)
        curve = RGBCurve(1.5, MU, edit)
        np.testing.assert_allclose(edited_target(gold_base, [curve], MU, 1.5, 0.3), edit, atol=BLEND_ROUNDING)
        far = edited_target(gold_base, [curve], MU, 2.2, 0.3)
        np.testing.assert_allclose(far, gold_base.rgb(MU, 2.2), atol=BLEND_ROUNDING)
        halfway = edited_target(gold_base, [curve], MU, 1.65, 0.3)
        change = halfway[:, 0] - gold_base.rgb(MU, 1.65)[:, 0]
        assert 0.04 < change.max() < 0.06  # smoothstep(0.5) = 0.5 of the 0.1 bump
        # (not rounding: 0.05 +/- 0.01 allows for the [0, 1] clip of the bump)
        np.testing.assert_allclose(halfway[:, 1:], gold_base.rgb(MU, 1.65)[:, 1:], atol=BLEND_ROUNDING)

    def test_n_dimensional(self, gold_base):
        curve = RGBCurve(1.5, MU, gold_base.rgb(MU, 1.5))
        M, E = np.meshgrid(MU, np.linspace(1, 2.5, 7), indexing="xy")
        assert edited_target(gold_base, [curve], M, E).shape == M.shape + (3,)
