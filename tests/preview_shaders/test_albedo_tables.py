"""
The albedo tables of the editor's split-sum preview, in moderngl: the
GLSL passes ``albedo_table.frag`` (model, adjusted Lazanyi and coat rows,
from the LUT) and ``reference_albedo.frag`` (the GGX lobe with the
spectral reference texture as its Fresnel: ``cf_reference_albedo``,
``cf_sample_visible_normal``, ``cf_hammersley``) against numpy
(:mod:`fitting.shading.ibl`) at their NdotV nodes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fitting.fits.curves_base import curve_base_from_nk
from fitting.models.baselines import baseline_inputs
from fitting.models.coated_conductor import collapse_to_eta_i
from fitting.models.pack import pack_from_json
from fitting.optics.fresnel import fresnel_dielectric
from fitting.optics.library import library_material
from fitting.shading.ibl import (
    default_lut,
    directional_albedo,
    split_sum_lazanyi,
    split_sum_model,
    split_sum_schlick,
)
from preview_shaders.gl import RenderThread, check_gl_error, read_float_target
from preview_shaders.preview import padded_words
from preview_shaders.shading import upload_lut
from precision import GLSL_F32_BOUND

pytestmark = [pytest.mark.gl, pytest.mark.numeric]

GOLDEN = Path(__file__).resolve().parents[1] / "golden" / "Au_golden.json"
NODES = 127  # as the editor's: twice the LUT's 64 NdotV nodes, less one
MU = (np.arange(NODES) / (NODES - 1)) ** 2
# The split-sum rows: the model's GLSL_F32_BOUND (tests/precision.py) plus
# the LUT fetched as a float32 texture at its nodes (<= 2 u32) and the
# split-sum's three-term combination (3 * 2 u32): 1e-5 + 5e-7. The
# reference_albedo pass sums 2048 GGX samples in float32 in sequence:
# worst case N u32 = 1.2e-4, but the roundings of a sum of positive terms
# of similar size are independent, so 4 standard deviations are
# 4 sqrt(N) u32 = 1.1e-5, with the model's 1e-5: 2e-5 in all.
# (The same figures as docs/editor.md's table for the browser.)
TOLERANCE = 2 * GLSL_F32_BOUND
"""As the LUT's own parity (test_ibl_parity): float32 lookups and sums
against float64 numpy on the same texels."""


@pytest.fixture(scope="module")
def thread():
    with RenderThread("test-albedo-tables") as render_thread:
        yield render_thread


@pytest.fixture(scope="module")
def gold():
    return pack_from_json(GOLDEN.read_text())[0]


def _render(state, fragment, rows, uniforms, textures):
    ctx = state.ctx
    program, vao = state.program(fragment)
    for name, value in uniforms.items():
        if name in program:
            program[name].value = value
    made = []
    for unit, (name, make) in enumerate(textures.items()):
        texture = make(state)
        texture.use(location=unit)
        program[name].value = unit
        made.append(texture)
    fbo, targets = state.float_targets((NODES, rows), 1)
    try:
        fbo.use()
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        out = read_float_target(fbo, 0, NODES, rows)[..., :3].astype(np.float64)
        check_gl_error(ctx)
    finally:
        state.release_targets(fbo, targets)
        for texture in made:
            texture.release()
    return out


def _tables(thread, gold, nk, eta_i, roughness, coat_roughness):
    b = baseline_inputs(nk)
    lut = default_lut()
    uniforms = {
        "u_resolution": (float(NODES), 3.0),
        "u_eta_i": eta_i,
        "u_roughness": roughness,
        "u_coat_roughness": coat_roughness,
        "cf_words": padded_words(gold).tolist(),
        "cf_eta_i_range": tuple(gold.eta_i_range),
        "cf_F0_air": tuple(b["F0_air"]),
        "cf_F82_air": tuple(b["F82_air"]),
        "cf_alpha_range": lut.alpha_range,
    }
    return thread.call(_render, "albedo_table.frag", 3, uniforms, {"cf_lut": lambda state: upload_lut(state, lut)})


@pytest.mark.parametrize("eta_i, roughness, coat_roughness", [(1.5, 0.45, 0.2), (2.2, 0.9, 0.6), (1.0, 0.1, 0.3)])
def test_albedo_table_rows_are_the_numpy_split_sums(thread, gold, eta_i, roughness, coat_roughness):
    nk = library_material("Au")
    got = _tables(thread, gold, nk, eta_i, roughness, coat_roughness)
    p = collapse_to_eta_i(gold.coefficients.astype(np.float64), eta_i, gold.eta_i_range)[..., 0]
    np.testing.assert_allclose(got[0], split_sum_model(MU, roughness, p[0], p[1], p[2]), atol=TOLERANCE)
    b = baseline_inputs(nk)
    np.testing.assert_allclose(
        got[1], split_sum_lazanyi(MU, roughness, eta_i, b["F0_air"], b["F82_air"]), atol=TOLERANCE
    )
    F0c = ((eta_i - 1.0) / (eta_i + 1.0)) ** 2
    coat = split_sum_schlick(MU, coat_roughness, np.full(3, F0c)) if eta_i > 1.0 else np.zeros((NODES, 3))
    np.testing.assert_allclose(got[2], coat, atol=TOLERANCE)


def test_mirrors_are_their_fresnel(thread, gold):
    """Roughness 0 is a mirror: the rows hold the model, Lazanyi and the exact dielectric."""
    from fitting.models.baselines import lazanyi_adjusted
    from fitting.models.coated_conductor import coated_conductor_model

    nk = library_material("Au")
    got = _tables(thread, gold, nk, 1.7, 0.0, 0.0)
    model = coated_conductor_model(MU, 1.7, gold.coefficients.astype(np.float64), gold.eta_i_range)
    np.testing.assert_allclose(got[0], model, atol=TOLERANCE)
    b = baseline_inputs(nk)
    np.testing.assert_allclose(got[1], lazanyi_adjusted(MU, 1.7, b["F0_air"], b["F82_air"]), atol=TOLERANCE)
    np.testing.assert_allclose(got[2], np.repeat(fresnel_dielectric(MU, 1.0, 1.7)[:, None], 3, axis=1), atol=TOLERANCE)


@pytest.mark.parametrize("eta_i, roughness", [(1.5, 0.45), (2.4, 0.05), (1.2, 1.0)])
def test_reference_albedo_is_the_numpy_directional_albedo(thread, eta_i, roughness):
    base = curve_base_from_nk(library_material("Cu"), (1.0, 2.5))
    RGB = np.ascontiguousarray(base.RGB, dtype="f4")
    uniforms = {
        "u_resolution": (float(NODES), 1.0),
        "u_eta_i": eta_i,
        "u_roughness": roughness,
        "u_samples": 2048,
        "u_reference_eta_i_range": tuple(base.eta_i_range),
    }

    def texture(state):
        made = state.ctx.texture((RGB.shape[1], RGB.shape[0]), 3, RGB.tobytes(), dtype="f4")
        made.filter = (state.ctx.NEAREST, state.ctx.NEAREST)
        return made

    got = thread.call(_render, "reference_albedo.frag", 1, uniforms, {"u_reference": texture})[0]
    expected = directional_albedo(MU, roughness, lambda VdotH: base.rgb(VdotH, eta_i))
    assert expected.min() > 0.05  # so an absolute bound is meaningful
    np.testing.assert_allclose(got, expected, atol=TOLERANCE)
    # At roughness 0 the pass writes the reference itself (a mirror).
    uniforms["u_roughness"] = 0.0
    mirror = thread.call(_render, "reference_albedo.frag", 1, uniforms, {"u_reference": texture})[0]
    np.testing.assert_allclose(mirror, base.rgb(MU, eta_i), atol=TOLERANCE)
