"""fitting.fits.curves_input: validated curves."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.fits.curves_input import CURVE_MIN_SAMPLES, RGBCurve, check_curves

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

ANGLE = np.linspace(0.0, 90.0, 46)

MU = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))


class TestRGBCurve:
    def test_sorted_and_read_only(self):
        curve = RGBCurve(1.5, MU, np.full((MU.size, 3), 0.5))
        assert np.all(np.diff(curve.cos_theta) > 0)
        assert not curve.cos_theta.flags.writeable and not curve.rgb.flags.writeable

    def test_from_angles_matches_cos_theta(self):
        rgb = np.linspace(0.2, 1.0, ANGLE.size)[:, None].repeat(3, axis=1)
        a = RGBCurve.from_angles(1.5, ANGLE, rgb)
        b = RGBCurve(1.5, MU, rgb)
        np.testing.assert_allclose(a.cos_theta, b.cos_theta, atol=1e-15)  # cos of
        # degrees * pi / 180: <= 4 ulps of cos (any SIMD) + 2 roundings = 7 u64 = 8e-16
        np.testing.assert_array_equal(a.rgb, b.rgb)
        assert a.cos_theta[0] == 0.0  # 90 degrees is exactly grazing

    def test_above_one_names_the_place(self):
        rgb = np.full((MU.size, 3), 0.5)
        rgb[12, 0] = 1.2
        with pytest.raises(
            ValueError, match=r"`curve\.rgb\[\d+\]\[0\]` \(R at cos_theta .*\) must lie in \[0, 1\], got 1\.2"
        ):
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
