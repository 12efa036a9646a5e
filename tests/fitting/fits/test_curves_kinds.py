"""Curve fits of the rgb-conductor kind (``fit_curves(..., model="rgb-conductor")``)."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.colour.delta_e import delta_E_map
from fitting.fits.curves import fit_curves, whole_target_error
from fitting.fits.curves_base import curve_base_from_coefficients, curve_base_from_nk
from fitting.fits.curves_input import check_curves
from fitting.models.rgb_conductor import rgb_conductor_model
from fitting.optics.library import library_material

pytestmark = pytest.mark.numeric  # run again with other CPUs' kernels (scripts/test --other-cpus)

MU = np.linspace(0.0, 1.0, 13)


def curve(base, eta_i, scale=(1.0, 1.0, 1.0)):
    rgb = base.rgb(MU, np.full_like(MU, eta_i)) * np.asarray(scale)
    return {"eta_i": eta_i, "cos_theta": MU.tolist(), "rgb": np.clip(rgb, 0.0, 1.0).tolist()}


@pytest.fixture(scope="module")
def copper():
    return curve_base_from_nk(library_material("Cu"))


class TestRGBConductorCurveFits:
    def test_an_unedited_curve_is_followed_closely(self, copper):
        # The kind follows the reference under the coat to ~0.03 on the library:
        # fitted to the base's own curve it must do about as well.
        result = fit_curves([curve(copper, 1.5)], copper, model="rgb-conductor")
        assert result.model == result.packed.model == "rgb-conductor"
        assert result.coefficients_float16.shape == (2, 3)
        assert result.coefficients_float16.dtype == np.float16
        # A fit-quality figure (rgb-conductor fits of exact curves), not precision.
        assert result.metrics["delta_E_mean"] < 0.15
        assert result.metrics["target"]["delta_E_mean"] < 0.15

    def test_reported_figures_are_the_kinds_own_model(self, copper):
        curves = [curve(copper, 1.3, (0.95, 1.0, 1.05))]
        result = fit_curves(curves, copper, model="rgb-conductor")
        n, k = result.coefficients_float16.astype(np.float64)
        model = rgb_conductor_model(MU, 1.3, result.coefficients_float16)
        target = np.asarray(curves[0]["rgb"])
        assert result.metrics["by_curve"][0]["delta_E_mean"] == pytest.approx(
            float(delta_E_map(target, model).mean()), rel=1e-9
        )  # the same Delta E
        # by another path: per sample ~1e-12 (1e4 per unit RGB x 1e-16), a mean of
        # Delta E ~0.1: rel <= 1e-10, so 1e-9 holds with a 10x margin
        whole = whole_target_error(
            copper, check_curves(curves), result.coefficients_float16, 0.5, model="rgb-conductor"
        )
        assert whole == result.metrics["target"]
        assert np.all(n > 0) and np.all(k >= 0)

    def test_always_a_reflectance(self, copper):
        # An extreme edit: the kind cannot leave [0, 1], whatever it is fitted to.
        result = fit_curves([curve(copper, 2.0, (0.0, 2.0, 3.0))], copper, model="rgb-conductor")
        values = result.metrics["target"]
        assert 0.0 <= values["model_min"] and values["model_max"] <= 1.0

    @pytest.mark.slow  # 2.3 s in the quick loop's run (two full guarded refits)
    def test_more_accurate_kind_is_not_worse_than_coated_on_the_reference(self, copper):
        curves = [curve(copper, 1.5)]
        rgb = fit_curves(curves, copper, model="rgb-conductor").metrics["target"]["delta_E_mean"]
        coated = fit_curves(curves, copper).metrics["target"]["delta_E_mean"]
        assert rgb <= coated + 0.05

    def test_without_a_base(self, copper):
        result = fit_curves([curve(copper, 1.2), curve(copper, 2.2)], None, model="rgb-conductor")
        assert result.packed.model == "rgb-conductor" and "target" not in result.metrics
        # A fit-quality figure (rgb-conductor fits of exact curves), not precision.
        assert result.metrics["delta_E_mean"] < 0.3

    def test_a_stored_rgb_conductor_model_is_a_base(self, copper):
        first = fit_curves([curve(copper, 1.5)], copper, model="rgb-conductor")
        base = curve_base_from_coefficients(
            first.coefficients_float16, copper.eta_i_range, "Cu rgb", model="rgb-conductor"
        )
        M, E = np.meshgrid(MU, np.array([1.0, 2.5]))
        expected = rgb_conductor_model(M, E, first.coefficients_float16)
        # The base's bilinear table of the model (see BASE_INTERPOLATION_BOUND in
        # test_curves_base: h^2 / 8 |F''|, the smooth rgb-conductor model ~50x
        # below the conductors' 2e-4 bound near grazing); interpolation, not rounding.
        assert np.allclose(base.rgb(M, E), expected, atol=1e-4)

    def test_unknown_kind_refused(self, copper):
        with pytest.raises(ValueError, match="`model` must be one of coated-conductor, rgb-conductor"):
            fit_curves([curve(copper, 1.5)], copper, model="coated")
