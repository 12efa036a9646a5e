"""
The GLSL split sum is the numpy one: the LUT texture decoded by
``texelFetch`` equals numpy's float32 texels bit for bit, and
``cf_split_sum_model`` over 128 x 128 (NdotV, roughness) equals
:func:`fitting.shading.ibl.split_sum_model` on the shader's float32 inputs.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.shading.ibl import SplitSumLUT, generate_lut, split_sum_model
from preview_shaders.gl import RenderThread
from preview_shaders.shading import decode_lut_in_shader, evaluate_split_sum_grid
from precision import GLSL_F32_BOUND

pytestmark = [pytest.mark.gl, pytest.mark.numeric]

TOLERANCE = GLSL_F32_BOUND  # float32 GLSL against float64 numpy: derived in tests/precision.py


@pytest.fixture(scope="module")
def thread():
    with RenderThread("test-ibl-parity") as render_thread:
        yield render_thread


@pytest.fixture(scope="module")
def lut():
    # A small table keeps the test quick; the lookup is the same code.
    return generate_lut(shape=(16, 24, 32), samples=256)


def test_texture_decodes_exactly(thread, lut):
    decoded = decode_lut_in_shader(thread, lut)
    assert decoded.shape == lut.data.shape
    assert decoded.view(np.uint32).tolist() == lut.data.view(np.uint32).tolist()


def test_texture_decode_sees_a_changed_texel(thread, lut):
    data = lut.data.copy()
    data[5, 7, 9, 2] = np.nextafter(data[5, 7, 9, 2], np.float32(1.0))
    decoded = decode_lut_in_shader(thread, SplitSumLUT(data, lut.alpha_range))
    assert decoded[5, 7, 9, 2] != lut.data[5, 7, 9, 2]


@pytest.mark.parametrize(
    "F0, a, alpha",
    [
        ((0.37, 0.38, 0.39), (0.6, 0.55, 0.0), (4.8, 4.8, 5.0)),  # Cr at eta_i 1.5
        ((0.95, 0.6, 0.2), (3.0, 1.5, -0.4), (0.3, 2.05, 20.0)),  # clamps at both alpha ends
        ((0.5, 0.5, 0.5), (1.0, 1.0, 1.0), (0.5, 12.0, 1.7)),  # on the slices
    ],
)
def test_split_sum_matches_numpy(thread, lut, F0, a, alpha):
    E, mu, r = evaluate_split_sum_grid(thread, lut, F0, a, alpha)
    expected = split_sum_model(mu.astype(np.float64), r.astype(np.float64), F0, a, alpha, lut)
    assert np.all(np.isfinite(E))
    assert np.abs(E - expected).max() <= TOLERANCE


def test_detects_a_changed_alpha(thread, lut):
    F0, a, alpha = (0.37, 0.38, 0.39), (0.6, 0.55, 0.2), (4.8, 4.8, 5.0)
    E, mu, r = evaluate_split_sum_grid(thread, lut, F0, a, alpha)
    other = split_sum_model(mu.astype(np.float64), r.astype(np.float64), F0, a, (4.8, 4.8, 5.01), lut)
    assert np.abs(E - other).max() > TOLERANCE  # the bound is tight enough to see alpha + 0.01


def test_every_split_sum_timing_variant_renders(thread, lut):
    from preview_shaders.shading import SPLIT_SUM_VARIANTS, time_split_sum

    samples = time_split_sum(
        thread, lut, (0.5,) * 3, (0.2,) * 3, (5.0,) * 3, (0.5,) * 3, (0.3,) * 3, (0.6,) * 3, 64, 32, 2
    )
    assert set(samples) == set(SPLIT_SUM_VARIANTS)
    for values in samples.values():
        assert values.shape == (2, 3) and np.all(np.isfinite(values)) and np.all(values[:, 1] > 0)
