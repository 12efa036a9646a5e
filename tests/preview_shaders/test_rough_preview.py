"""
Rough and coated preview spheres (preview_shaders.rough, preview_rough.frag):
values against the numpy split sum, the coat's limit, prefiltering, the
reference under the same lighting and input checks.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fitting.models.coated_conductor import collapse_to_eta_i
from fitting.models.pack import pack_from_json
from fitting.optics.library import library_material
from fitting.shading.ibl import split_sum_coated, split_sum_lazanyi, split_sum_model
from fitting.models.baselines import baseline_inputs
from preview_shaders.gl import RenderThread
from preview_shaders.preview import PreviewRenderer, reference_image
from preview_shaders.rough import equirect_directions, prefilter_equirect, reference_albedo_table
from precision import GLSL_F32_BOUND

pytestmark = [pytest.mark.gl, pytest.mark.numeric]

# The split-sum preview in float32 GLSL against numpy: the model's
# GLSL_F32_BOUND (tests/precision.py) plus the LUT texture's bilinear
# filtering in float32 (weights and three products: ~6 u32 of values <= 1)
# and the split sum's combination: 1e-5 + 1e-6, with the same 2x of the
# albedo tables: 2e-5 (docs/editor.md's figure for the browser).
SPLIT_SUM_BOUND = 2 * GLSL_F32_BOUND

GOLDEN = Path(__file__).resolve().parents[2] / "tests" / "golden"


@pytest.fixture(scope="module")
def renderer():
    with RenderThread("test-rough-preview") as thread:
        yield PreviewRenderer(thread)


@pytest.fixture(scope="module")
def gold():
    return pack_from_json((GOLDEN / "Au_golden.json").read_text())[0]


@pytest.fixture(scope="module")
def nk():
    return library_material("Au")


def _params(packed, eta_i):
    p = collapse_to_eta_i(packed.coefficients.astype(np.float64), eta_i, packed.eta_i_range)[..., 0]
    return p[0], p[1], p[2]


class TestWhiteSky:
    """The white sky prefilters to 1: the sphere shows the directional albedo."""

    @pytest.mark.parametrize("roughness", [0.3, 0.8])
    def test_immersed_is_the_numpy_split_sum(self, renderer, gold, roughness):
        result = renderer.render_preview(gold, None, 1.5, 65, roughness=roughness)
        mu = result.cos_theta[result.mask].astype(np.float64)
        expected = split_sum_model(mu, roughness, *_params(gold, 1.5))
        np.testing.assert_allclose(result.model[result.mask], expected, atol=SPLIT_SUM_BOUND)
        np.testing.assert_array_equal(result.radiance[result.mask], 1.0)

    def test_coated_is_the_numpy_coated_split_sum(self, renderer, gold):
        result = renderer.render_preview(gold, None, 2.0, 65, roughness=0.4, mode="coated", coat_roughness=0.2)
        mu = result.cos_theta[result.mask].astype(np.float64)
        expected = split_sum_coated(mu, 0.4, *_params(gold, 2.0), 2.0, 0.2)
        np.testing.assert_allclose(result.model[result.mask], expected, atol=SPLIT_SUM_BOUND)

    def test_coated_at_eta_1_equals_immersed(self, renderer, gold):
        immersed = renderer.render_preview(gold, None, 1.0, 65, roughness=0.5)
        coated = renderer.render_preview(gold, None, 1.0, 65, roughness=0.5, mode="coated", coat_roughness=0.7)
        np.testing.assert_allclose(coated.image, immersed.image, atol=1e-6)  # eta_i = 1:
        # the coat's terms are identities up to a few float32 roundings (3e-7)

    def test_lazanyi_split_is_the_numpy_lazanyi_split_sum(self, renderer, gold, nk):
        result = renderer.render_preview(gold, nk, 1.5, 65, "lazanyi", roughness=0.5)
        mu = result.cos_theta[result.mask].astype(np.float64)
        b = baseline_inputs(nk)
        expected = split_sum_lazanyi(mu, 0.5, 1.5, b["F0_air"], b["F82_air"])
        np.testing.assert_allclose(result.comparison[result.mask], expected, atol=SPLIT_SUM_BOUND)
        assert np.array_equal(result.image[:, :32], result.model[:, :32])
        assert np.array_equal(result.image[:, 32:], result.comparison[:, 32:])

    def test_reference_near_mirror_is_the_smooth_reference(self, renderer, gold, nk):
        rough = renderer.render_preview(
            gold, nk, 1.5, 65, "reference", roughness=0.0, mode="coated"
        )  # coated path, rough shader, r = 0
        smooth = renderer.render_preview(gold, nk, 1.5, 65, "reference")
        # The smooth reference at eta_i 1.5 is the immersed mirror; the coated
        # reference at r = 0 is the coat over it. Check the immersed table instead:
        mu = smooth.cos_theta[smooth.mask].astype(np.float64)
        table_mu, table = reference_albedo_table(nk, 1.5, 0.0)
        E = np.stack([np.interp(mu, table_mu, table[:, c]) for c in range(3)], axis=-1)
        F = reference_image(nk, smooth.cos_theta, smooth.mask, smooth.radiance, 1.5)[smooth.mask]
        central = mu > 0.3  # grazing: even a 0.02 lobe masks and shadows
        # Not rounding: a 0.02 lobe against the mirror (the lobe's blur of the
        # reference's slope), a model claim.
        np.testing.assert_allclose(E[central], F[central], atol=5e-3)
        assert rough.delta_E_mean is not None and np.isfinite(rough.delta_E_mean)

    def test_reference_agrees_with_the_model(self, renderer, gold, nk):
        result = renderer.render_preview(gold, nk, 1.5, 65, "reference", roughness=0.5)
        assert result.delta_E_mean < 1.0  # the fit's quality, now under a rough lobe
        assert 0.0 <= result.flip_mean < 0.1  # product figures, not precision


class TestPrefilter:
    def test_constant_is_preserved(self):
        out = prefilter_equirect(np.full((8, 16, 3), 0.7), 5)
        np.testing.assert_array_equal(out, np.float32(0.7))

    def test_blur_grows_with_roughness_and_keeps_energy(self):
        image = np.zeros((32, 64, 3))
        image[12:14, 30:34] = 10.0  # a small bright light
        out = prefilter_equirect(image, 5).astype(np.float64)
        _, omega = equirect_directions(64, 32)
        energy = [float(np.sum(o[..., 0] * omega)) for o in out]
        peaks = [float(o[..., 0].max()) for o in out]
        assert all(a > b for a, b in zip(peaks, peaks[1:]))
        # D max(R.L, 0) over the sphere is not exactly symmetric in R and L
        # for wide lobes; energy stays within a few percent.
        np.testing.assert_allclose(energy[1:3], energy[0], rtol=0.05)

    def test_studio_sphere_gets_smoother(self, renderer, gold):
        def roughness_texture(r):
            result = renderer.render_preview(gold, None, 1.5, 96, environment="studio", roughness=r)
            inner = result.mask & np.roll(result.mask, 1, 0) & np.roll(result.mask, 1, 1)
            g = result.model[..., 1]
            grad = np.abs(g - np.roll(g, 1, 0)) + np.abs(g - np.roll(g, 1, 1))
            return float(grad[inner].mean())

        sharp, medium, blurred = (roughness_texture(r) for r in (0.1, 0.4, 0.8))
        assert sharp > medium > blurred


class TestChecks:
    @pytest.mark.parametrize(
        "kwargs, message",
        [
            ({"roughness": 1.5}, "`roughness` must lie in \\[0, 1\\], got 1.5"),
            ({"roughness": float("nan")}, "`roughness` must lie in"),
            ({"coat_roughness": -0.1}, "`coat_roughness` must lie in \\[0, 1\\]"),
            ({"mode": "layered"}, "`mode` must be one of immersed, coated"),
            ({"roughness": "0.3"}, "`roughness` must be a number"),
        ],
    )
    def test_bad_input(self, renderer, gold, kwargs, message):
        with pytest.raises(ValueError, match=message):
            renderer.render_preview(gold, None, 1.5, 64, **kwargs)


class TestCommandLine:
    def _run(self, *args):
        from conftest import run_command

        return run_command("preview_shaders", "render", *args, cwd=GOLDEN.parents[1])

    def test_rough_coated_render_matches_the_library(self, renderer, gold, tmp_path):
        from PIL import Image

        from preview_shaders.display import ACEScg_to_sRGB, to_uint8

        out = tmp_path / "rough.png"
        run = self._run(
            "--fit",
            str(GOLDEN / "Au_golden.json"),
            "--eta-i",
            "1.8",
            "--size",
            "64",
            "--roughness",
            "0.45",
            "--mode",
            "coated",
            "--coat-roughness",
            "0.2",
            "-o",
            str(out),
        )
        assert run.returncode == 0, run.stderr
        assert "coated, roughness 0.45, coat roughness 0.2" in run.stdout
        expected = renderer.render_preview(gold, None, 1.8, 64, roughness=0.45, mode="coated", coat_roughness=0.2)
        np.testing.assert_array_equal(
            np.asarray(Image.open(out).convert("RGB")), to_uint8(ACEScg_to_sRGB(expected.image))
        )

    def test_bad_roughness_is_an_error(self, tmp_path):
        run = self._run(
            "--fit", str(GOLDEN / "Au_golden.json"), "--size", "64", "--roughness", "2", "-o", str(tmp_path / "x.png")
        )
        assert run.returncode == 2
        assert "`roughness` must lie in [0, 1], got 2.0" in run.stderr
        assert not (tmp_path / "x.png").exists()
