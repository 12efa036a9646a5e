"""
The shader is the model: the GLSL variants evaluated into float32 targets
over a 256 x 256 grid of (cos theta, eta_i) against the numpy definitions,
and the packed halves decoded in GLSL against numpy's float16 values.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.models.baselines import lazanyi_adjusted, schlick
from fitting.models.coated_conductor import (
    coated_conductor_model,
    collapse_to_eta_i,
    model_from_parameters,
)
from fitting.models.pack import PackedMaterial, halves_to_uint32, to_float16
from fitting.optics.fresnel import fresnel_conductor
from preview_shaders.evaluate import (
    CONSTANTS_SUFFIX,
    TIMING_VARIANTS,
    time_variants,
    decode_halves_in_shader,
    evaluate_grid,
    padded_coefficients,
    shader_inputs,
)
from preview_shaders.gl import RenderThread, load_shader_source
from precision import GLSL_F32_BOUND

pytestmark = [pytest.mark.gl, pytest.mark.numeric]

TOLERANCE = GLSL_F32_BOUND  # float32 GLSL against float64 numpy: derived in tests/precision.py
"""Absolute: float32 arithmetic in the shader against float64 numpy."""

# 256 values of cos theta over [0, 1] (both ends included) and of eta_i over
# [1, 3], so the clamp of t outside the fitted domain is exercised too.
MU_AXIS = (0.0, 1.0 / 255.0, 256)
ETA_AXIS = (1.0, 2.0 / 255.0, 256)


@pytest.fixture(scope="module")
def thread():
    with RenderThread("test-shader-parity") as render_thread:
        yield render_thread


def _coefficients(seed: int) -> np.ndarray:
    """Plausible coefficients: F0 in (0.3, 0.95), a in (0, 4), alpha in (2, 12)."""
    rng = np.random.default_rng(seed)
    C = np.empty((3, 3, 3))
    C[0] = np.column_stack([rng.uniform(0.3, 0.95, 3), rng.uniform(-0.2, 0.1, 3), rng.uniform(-0.05, 0.05, 3)])
    C[1] = np.column_stack([rng.uniform(0.0, 4.0, 3), rng.uniform(-1.0, 1.0, 3), rng.uniform(-0.5, 0.5, 3)])
    C[2] = np.column_stack([rng.uniform(2.0, 12.0, 3), rng.uniform(-2.0, 2.0, 3), rng.uniform(-1.0, 1.0, 3)])
    return to_float16(C)


MATERIALS = {
    "random-0": PackedMaterial("r0", _coefficients(0), (1.0, 2.5)),
    "random-1": PackedMaterial("r1", _coefficients(1), (1.2, 2.0)),
    "degree-1": PackedMaterial("d1", _coefficients(2)[:, :, :2], (1.0, 2.5)),
    "single-index": PackedMaterial("s", _coefficients(3), (1.5, 1.5)),
    # alpha clamps to ALPHA_MIN over part of the domain.
    "alpha-clamped": PackedMaterial(
        "c", to_float16(np.concatenate([_coefficients(4)[:2], [[[0.5, -3.0, 0.0]] * 3]])), (1.0, 2.5)
    ),
}


def _numpy_inputs(mu, eta):
    return mu.astype(np.float64), eta.astype(np.float64)


class TestHalvesDecoding:
    def test_decodes_exactly_numpy_float16(self, thread):
        special = np.array(
            [
                0.0,
                -0.0,
                1.0,
                -1.0,
                65504.0,
                -65504.0,
                2.0**-24,
                -(2.0**-24),
                2.0**-14,
                6.103515625e-05 - 2.0**-24,
                0.333251953125,
                1.0009765625,
            ],
            dtype=np.float16,
        )
        rng = np.random.default_rng(7)
        random = (rng.standard_normal(15) * 10.0).astype(np.float16)
        halves = np.concatenate([special, random]).reshape(3, 3, 3)
        decoded = decode_halves_in_shader(thread, halves_to_uint32(halves))
        expected = halves.astype(np.float32).ravel()
        assert decoded.view(np.uint32).tolist() == expected.view(np.uint32).tolist()

    def test_order_matters(self, thread):
        halves = np.arange(27, dtype=np.float16).reshape(3, 3, 3)
        decoded = decode_halves_in_shader(thread, halves_to_uint32(halves))
        np.testing.assert_array_equal(decoded, np.arange(27, dtype=np.float32))

    def test_rejects_wrong_word_count(self, thread):
        with pytest.raises(ValueError, match="`words` must hold 14 uint32"):
            decode_halves_in_shader(thread, np.zeros(13, dtype=np.uint32))


class TestCoatedConductorModel:
    @pytest.mark.parametrize("variant", ["packed", "floats", "lean"])
    @pytest.mark.parametrize("name", sorted(MATERIALS))
    def test_matches_numpy_model(self, thread, variant, name):
        material = MATERIALS[name]
        F, mu, eta = evaluate_grid(thread, variant, shader_inputs(material), MU_AXIS, ETA_AXIS)
        assert F.shape == (256, 256, 3) and F.dtype == np.float32
        # The shader's grid coordinates in float32 (an index times a step, an
        # offset): <= 3 roundings of values <= 3, 3 * 3 u32 = 5.4e-7 < 1e-6.
        np.testing.assert_allclose(mu[0], np.arange(256) / 255.0, atol=1e-6)
        np.testing.assert_allclose(eta[:, 0], 1.0 + 2.0 * np.arange(256) / 255.0, atol=1e-6)
        expected = coated_conductor_model(
            *_numpy_inputs(mu, eta), material.coefficients.astype(np.float64), material.eta_i_range
        )
        assert np.all(np.isfinite(F))
        assert np.abs(F - expected).max() <= TOLERANCE

    @pytest.mark.parametrize("variant", ["collapsed", "collapsed_lean"])
    @pytest.mark.parametrize("eta_i", [1.0, 1.5, 2.2, 2.5])
    def test_scene_specialised_matches_collapse(self, thread, eta_i, variant):
        material = MATERIALS["random-0"]
        inputs = shader_inputs(material, collapse_eta_i=eta_i)
        F, mu, _ = evaluate_grid(thread, variant, inputs, MU_AXIS, (eta_i, 0.0, 4))
        assert np.all(np.isfinite(F))
        P = collapse_to_eta_i(material.coefficients.astype(np.float64), eta_i, material.eta_i_range)
        expected = model_from_parameters(mu.astype(np.float64)[..., None], P[0, :, 0], P[1, :, 0], P[2, :, 0])
        assert np.abs(F - expected).max() <= TOLERANCE
        general = coated_conductor_model(
            mu.astype(np.float64), eta_i, material.coefficients.astype(np.float64), material.eta_i_range
        )
        assert np.abs(F - general).max() <= TOLERANCE

    @pytest.mark.parametrize("variant", ["packed", "floats", "lean"])
    @pytest.mark.parametrize("name", ["random-1", "single-index"])
    def test_compiled_in_constants_match_numpy_model(self, thread, variant, name):
        # The material's values as GLSL constants (what an exported snippet ships).
        material = MATERIALS[name]
        F, mu, eta = evaluate_grid(thread, variant, shader_inputs(material), MU_AXIS, ETA_AXIS, constants=True)
        expected = coated_conductor_model(
            *_numpy_inputs(mu, eta), material.coefficients.astype(np.float64), material.eta_i_range
        )
        assert np.all(np.isfinite(F)) and np.abs(F - expected).max() <= TOLERANCE

    def test_detects_a_one_ulp_change_of_a_coefficient(self, thread):
        material = MATERIALS["random-0"]
        F, mu, eta = evaluate_grid(thread, "packed", shader_inputs(material), MU_AXIS, ETA_AXIS)
        changed = material.coefficients.astype(np.float16).copy()
        changed[0, 1, 0] = np.nextafter(changed[0, 1, 0], np.float16(2.0))
        other = coated_conductor_model(*_numpy_inputs(mu, eta), changed.astype(np.float64), material.eta_i_range)
        assert np.abs(F - other).max() > TOLERANCE

    def test_degree_padding_is_the_same_model(self):
        C = MATERIALS["degree-1"].coefficients
        padded = padded_coefficients(C)
        assert padded.shape == (3, 3, 3) and np.all(padded[:, :, 2] == 0)
        np.testing.assert_array_equal(padded[:, :, :2], C)


class TestBaselines:
    F0_air = np.array([0.95, 0.64, 0.29])
    F82_air = np.array([0.91, 0.70, 0.45])

    @pytest.mark.parametrize("constants", [False, True])
    @pytest.mark.parametrize("variant", ["lazanyi", "lazanyi_lean"])
    def test_lazanyi_adjusted_matches_numpy(self, thread, variant, constants):
        inputs = shader_inputs(MATERIALS["random-0"], F0_air=self.F0_air, F82_air=self.F82_air)
        F, mu, eta = evaluate_grid(thread, variant, inputs, MU_AXIS, ETA_AXIS, constants=constants)
        expected = lazanyi_adjusted(*_numpy_inputs(mu, eta), self.F0_air, self.F82_air)
        assert np.abs(F - expected).max() <= TOLERANCE

    def test_schlick_matches_numpy(self, thread):
        inputs = shader_inputs(MATERIALS["random-0"], F0_air=self.F0_air)
        F, mu, _ = evaluate_grid(thread, "schlick", inputs, MU_AXIS, ETA_AXIS)
        expected = schlick(mu.astype(np.float64), self.F0_air)
        assert np.abs(F - expected).max() <= TOLERANCE

    @pytest.mark.parametrize(
        "n, k",
        [
            ((0.18, 0.42, 1.37), (3.42, 2.35, 1.77)),  # gold-like
            ((2.9, 3.1, 2.6), (3.3, 3.3, 3.2)),  # chromium-like
            ((1.2, 1.6, 2.8), (0.3, 0.1, 0.02)),  # weakly absorbing
        ],
    )
    def test_exact_conductor_matches_numpy(self, thread, n, k):
        inputs = shader_inputs(MATERIALS["random-0"], n=n, k=k)
        F, mu, eta = evaluate_grid(thread, "exact", inputs, MU_AXIS, ETA_AXIS)
        mu64, eta64 = _numpy_inputs(mu, eta)
        expected = fresnel_conductor(mu64[..., None], eta64[..., None], np.array(n), np.array(k))
        assert np.all(np.isfinite(F))
        assert np.abs(F - expected).max() <= TOLERANCE

    def test_dielectric_total_internal_reflection(self, thread):
        n, k = np.array([1.2, 1.6, 2.8]), np.zeros(3)
        inputs = shader_inputs(MATERIALS["random-0"], n=n, k=k)
        F, mu, eta = evaluate_grid(thread, "exact", inputs, MU_AXIS, ETA_AXIS)
        mu64, eta64 = _numpy_inputs(mu, eta)
        expected = fresnel_conductor(mu64[..., None], eta64[..., None], n, k)
        sin2_t = (eta64[..., None] / n) ** 2 * (1.0 - mu64[..., None] ** 2)
        # Past the critical angle: exactly the physical limit 1.
        assert np.all(F[sin2_t > 1.0001] == 1.0)
        # Away from it; at it, dR/dmu is unbounded and float32 rounding of
        # 1 - sin^2 dominates, so no fixed absolute tolerance applies there.
        far = np.abs(1.0 - sin2_t) > 1.0e-2
        assert np.abs(F - expected)[far].max() <= TOLERANCE


class TestShaderSources:
    def test_includes_resolved_and_defines_after_version(self):
        source = load_shader_source("evaluate.frag", {"CF_VARIANT": 3})
        lines = source.splitlines()
        assert lines[0].startswith("#version 430")
        assert lines[1] == "#define CF_VARIANT 3"
        assert "#include" not in source
        assert source.count("vec3 cf_coated_conductor_eq1(") == 1

    def test_unknown_shader_is_refused(self):
        with pytest.raises(ValueError, match="is not a shader"):
            load_shader_source("missing.frag")

    def test_unknown_variant_is_refused(self, thread):
        with pytest.raises(ValueError, match="`variant` must be one of"):
            evaluate_grid(thread, "cook", shader_inputs(MATERIALS["random-0"]), MU_AXIS, ETA_AXIS)


class TestTimingHarness:
    """The harness behind benchmarks/shader_cost.py renders every variant cleanly."""

    def test_every_timing_variant_renders(self, thread):
        names = TIMING_VARIANTS + tuple(v + CONSTANTS_SUFFIX for v in TIMING_VARIANTS)
        samples = time_variants(thread, shader_inputs(MATERIALS["random-0"]), names, 64, 32, 2)
        assert set(samples) == set(names)
        for values in samples.values():
            assert values.shape == (2, 3) and np.all(np.isfinite(values)) and np.all(values[:, 1] > 0)

    def test_unknown_variant_refused(self, thread):
        with pytest.raises(ValueError, match="`variants` must name"):
            time_variants(thread, shader_inputs(MATERIALS["random-0"]), ("phong",), 64, 32, 1)
