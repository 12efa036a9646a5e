"""
The rgb-conductor kind in GLSL is the numpy kind: ``cf_rgb_conductor_packed``
(6 float16 halves in 3 uint32, decoded with unpackHalf2x16) evaluated into a
float32 target over 256 x 256 (cos theta, eta_i) against
``fitting.models.rgb_conductor.rgb_conductor_model``, to 1e-5 like the
coated-conductor model.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.optics.library import library_material
from fitting.models.rgb_conductor import rgb_conductor_model
from fitting.models.pack import PackedMaterial, to_float16
from preview_shaders.evaluate import MODEL_VARIANTS, evaluate_grid, shader_inputs
from preview_shaders.gl import RenderThread, load_shader_source
from precision import GLSL_F32_BOUND

pytestmark = [pytest.mark.gl, pytest.mark.numeric]

TOLERANCE = GLSL_F32_BOUND  # float32 GLSL against float64 numpy: derived in tests/precision.py
"""Absolute: float32 arithmetic in the shader against float64 numpy."""

MU_AXIS = (0.0, 1.0 / 255.0, 256)
ETA_AXIS = (1.0, 2.0 / 255.0, 256)

MATERIALS = {
    "gold-like": ((0.26, 0.4727, 1.317), (3.029, 2.3125, 1.923)),
    "chromium-like": ((3.148, 3.1094, 2.381), (3.303, 3.33, 3.154)),
    "silver-like": ((0.0539, 0.0544, 0.044), (3.953, 3.559, 2.6875)),
    # k = 0 in blue and n below the coating's index: total internal reflection.
    "weakly-absorbing": ((1.2, 1.6, 2.8), (0.3, 0.1, 0.0)),
}


@pytest.fixture(scope="module")
def thread():
    with RenderThread("test-rgb-conductor-parity") as render_thread:
        yield render_thread


def _packed(name):
    n, k = MATERIALS[name]
    return PackedMaterial(name, to_float16([n, k]), (1.0, 2.5), model="rgb-conductor")


class TestRGBConductorPacked:
    @pytest.mark.parametrize("name", sorted(MATERIALS))
    def test_matches_numpy(self, thread, name):
        material = _packed(name)
        variant = MODEL_VARIANTS[material.model]
        F, mu, eta = evaluate_grid(thread, variant, shader_inputs(material), MU_AXIS, ETA_AXIS)
        assert F.shape == (256, 256, 3) and np.all(np.isfinite(F))
        expected = rgb_conductor_model(
            mu.astype(np.float64), eta.astype(np.float64), material.coefficients.astype(np.float64)
        )
        error = np.abs(F - expected)
        if name == "weakly-absorbing":
            # At the critical angle of the k = 0 channel dR/dmu is unbounded and
            # float32 rounding of 1 - sin^2 dominates; past it R is exactly 1.
            sin2 = (eta.astype(np.float64) / material.coefficients[0, 2]) ** 2 * (1 - mu.astype(np.float64) ** 2)
            assert np.all(F[..., 2][sin2 > 1.0001] == 1.0)
            error[..., 2] = np.where(np.abs(1.0 - sin2) > 1e-2, error[..., 2], 0.0)
        assert error.max() <= TOLERANCE

    def test_fitted_gold_matches_numpy(self, thread):
        from fitting.fits.rgb_conductor import fit_rgb_conductor

        material = fit_rgb_conductor(library_material("Au"), mu_samples=6, eta_samples=2).packed
        F, mu, eta = evaluate_grid(thread, "rgb_conductor", shader_inputs(material), MU_AXIS, ETA_AXIS)
        expected = rgb_conductor_model(
            mu.astype(np.float64), eta.astype(np.float64), material.coefficients.astype(np.float64)
        )
        assert np.abs(F - expected).max() <= TOLERANCE

    def test_halves_order_matters(self, thread):
        # Swapping n and k changes the colour: the decoding reads them in layout order.
        material = _packed("gold-like")
        swapped = PackedMaterial("s", material.coefficients[::-1].copy(), (1.0, 2.5), model="rgb-conductor")
        F, _, _ = evaluate_grid(thread, "rgb_conductor", shader_inputs(material), MU_AXIS, (1.5, 0.0, 1))
        G, _, _ = evaluate_grid(thread, "rgb_conductor", shader_inputs(swapped), MU_AXIS, (1.5, 0.0, 1))
        assert np.abs(F - G).max() > 0.05

    def test_source_has_one_definition(self):
        source = load_shader_source("evaluate.frag", {"CF_VARIANT": 6})
        assert source.count("vec3 cf_fresnel_conductor(") == 1
        assert source.count("vec3 cf_rgb_conductor_packed(") == 1
