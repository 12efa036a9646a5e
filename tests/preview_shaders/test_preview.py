"""
The preview sphere: geometry and values against the numpy model, golden
images (llvmpipe is deterministic), the spectral reference, input checks and
the command line.
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import run_command
from PIL import Image

from fitting.colour.reference import reference_ACEScg
from fitting.models.baselines import baseline_inputs, lazanyi_adjusted
from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import encode_pack, pack_from_json
from fitting.optics.library import library_material
from preview_shaders.gl import RenderThread
from preview_shaders.preview import PreviewRenderer, sphere_cos_theta
from precision import GLSL_F32_BOUND

pytestmark = [pytest.mark.gl, pytest.mark.numeric]

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = ROOT / "tests" / "golden"
sys.path.insert(0, str(GOLDEN))
from make_golden import CASES  # noqa: E402


@pytest.fixture(scope="module")
def renderer():
    with RenderThread("test-preview") as thread:
        yield PreviewRenderer(thread)


@pytest.fixture(scope="module")
def gold():
    return pack_from_json((GOLDEN / "Au_golden.json").read_text())[0]


@pytest.fixture(scope="module")
def nk():
    return library_material("Au")


def _model(packed, cos_theta, eta_i):
    return coated_conductor_model(
        np.asarray(cos_theta, dtype=np.float64),
        eta_i,
        packed.coefficients.astype(np.float64),
        packed.eta_i_range,
    )


class TestSphereValues:
    def test_centre_pixel_is_the_model_at_normal_incidence(self, renderer, gold):
        # Odd size: the centre pixel's centre is the sphere's centre.
        result = renderer.render_preview(gold, None, 1.5, 65)
        assert result.cos_theta[32, 32] == 1.0
        # mu = 1 exactly: pow(0, y) = 0, so only the t-polynomial's ~6 float32
        # roundings of terms <= ~1 remain: 6 * 2 u32 = 7e-7 < 1e-6.
        np.testing.assert_allclose(result.image[32, 32], _model(gold, 1.0, 1.5), atol=1e-6, rtol=0)

    def test_rim_pixel_is_the_model_at_its_cos_theta(self, renderer, gold):
        size = 65
        result = renderer.render_preview(gold, None, 2.0, size)
        cos_theta, mask = sphere_cos_theta(size)
        np.testing.assert_array_equal(result.mask, mask)
        row = 32
        column = int(np.flatnonzero(mask[row])[0])  # leftmost sphere pixel
        assert 0.0 < cos_theta[row, column] < 0.35
        np.testing.assert_allclose(
            # Near the rim: GLSL_F32_BOUND plus the float32 cos theta's error
            # (u32 / z, z >= ~0.1 here: 6e-7) times the model's slope there
            # (<= ~10): 1e-5 + 6e-6 < 2e-5.
            result.image[row, column],
            _model(gold, cos_theta[row, column], 2.0),
            atol=2e-5,
            rtol=0,
        )

    def test_every_sphere_pixel_is_the_model_under_the_white_sky(self, renderer, gold):
        result = renderer.render_preview(gold, None, 1.8, 64)
        cos_theta, mask = sphere_cos_theta(64)
        # cos theta = sqrt(1 - x^2 - y^2) in float32 against float64: ~4
        # roundings, the difference's condition 1 / z^2 near the rim: <= 1e-5
        # for the rim pixels' z >= ~0.08.
        assert np.abs(result.cos_theta - cos_theta)[mask].max() < 1e-5
        expected = _model(gold, result.cos_theta[mask], 1.8)
        assert np.abs(result.image[mask] - expected).max() <= GLSL_F32_BOUND
        np.testing.assert_array_equal(result.image[~mask], 1.0)

    def test_lazanyi_half_is_adjusted_lazanyi(self, renderer, gold, nk):
        result = renderer.render_preview(gold, nk, 2.5, 64, "lazanyi")
        right = np.zeros_like(result.mask)
        right[:, 32:] = True
        inputs = baseline_inputs(nk)
        expected = lazanyi_adjusted(
            result.cos_theta[result.mask & right].astype(np.float64),
            2.5,
            inputs["F0_air"],
            inputs["F82_air"],
        )
        assert np.abs(result.image[result.mask & right] - expected).max() <= GLSL_F32_BOUND
        left = result.mask & ~right
        np.testing.assert_array_equal(result.image[left], result.model[left])

    def test_split_drawn_by_the_shader_equals_the_composite(self, renderer, gold, nk):
        result = renderer.render_preview(gold, nk, 2.5, 64, "lazanyi", "studio")
        in_shader = renderer.render_split_in_shader(gold, nk, 2.5, 64, "studio")
        np.testing.assert_array_equal(in_shader, result.image)

    def test_studio_is_model_times_radiance(self, renderer, gold):
        result = renderer.render_preview(gold, None, 1.5, 64, environment="studio")
        mask = result.mask
        expected = _model(gold, result.cos_theta[mask], 1.5) * result.radiance[mask]
        assert np.abs(result.image[mask] - expected).max() <= GLSL_F32_BOUND
        # The studio is not uniform: it has lights and a floor.
        assert result.radiance[mask].max() > 1.0 and result.radiance[mask].min() < 0.1

    def test_outdoor_is_model_times_its_sky(self, renderer, gold):
        """The CLI's outdoor environment (a procedural sky and ground): the same
        model times radiance, bluer than red where the sphere sees the sky."""
        result = renderer.render_preview(gold, None, 1.5, 64, environment="outdoor")
        studio = renderer.render_preview(gold, None, 1.5, 64, environment="studio")
        mask = result.mask
        expected = _model(gold, result.cos_theta[mask], 1.5) * result.radiance[mask]
        assert np.abs(result.image[mask] - expected).max() <= GLSL_F32_BOUND
        assert not np.allclose(result.radiance[mask], studio.radiance[mask])
        top = result.radiance[:20][mask[:20]]  # the sphere's upper rim reflects the sky
        assert np.median(top[:, 2]) > np.median(top[:, 0])


class TestGolden:
    @pytest.mark.parametrize("name", sorted(CASES))
    def test_matches_golden_png(self, renderer, gold, nk, name):
        eta_i, size, compare, environment = CASES[name]
        result = renderer.render_preview(gold, nk, eta_i, size, compare, environment)
        rendered = np.asarray(Image.open(io.BytesIO(result.png)).convert("RGB"))
        golden = np.asarray(Image.open(GOLDEN / f"{name}.png").convert("RGB"))
        assert rendered.shape == golden.shape == (size, size, 3)
        np.testing.assert_array_equal(rendered, golden)

    def test_renders_are_bit_identical(self, renderer, gold, nk):
        first = renderer.render_preview(gold, nk, 2.0, 128, "lazanyi", "studio")
        second = renderer.render_preview(gold, nk, 2.0, 128, "lazanyi", "studio")
        assert first.image.tobytes() == second.image.tobytes()
        assert first.png == second.png


class TestReference:
    def test_reference_view_and_differences(self, renderer, gold, nk):
        result = renderer.render_preview(gold, nk, 1.5, 64, "reference")
        mask = result.mask
        expected = reference_ACEScg(nk, result.cos_theta[mask].astype(np.float64), 1.5)
        # The reference table (a spline within REFERENCE_TABLE_TOLERANCE = 1e-7)
        # stored in float32 (u32 of values <= 1) at float32 cos theta: 2e-7 < 1e-6.
        np.testing.assert_allclose(result.comparison[mask], expected, atol=1e-6, rtol=0)
        np.testing.assert_array_equal(result.comparison[~mask], 1.0)
        assert result.delta_E.shape == result.flip.shape == (64, 64)
        # Outside the sphere both images are the sky: no difference.
        assert np.all(result.delta_E[~mask] == 0.0)
        # Product figures (the fit's quality on the sphere), not precision.
        assert 0.0 < result.delta_E_mean < 1.0
        assert 0.0 < result.flip_mean < 0.1

    def test_a_wrong_material_is_far_from_the_reference(self, renderer, gold):
        chromium = library_material("Cr")
        result = renderer.render_preview(gold, chromium, 1.5, 64, "reference")
        assert result.delta_E_mean > 10.0


class TestInputChecks:
    @pytest.mark.parametrize(
        "kwargs, message",
        [
            ({"size": 63}, r"`size` must lie in \[64, 2048\], got 63"),
            ({"size": 2049}, r"`size` must lie in \[64, 2048\], got 2049"),
            ({"size": 100.0}, r"`size` must be an integer"),
            ({"eta_i": 0.99}, r"`eta_i` must lie in \[1, 3\], got 0.99"),
            ({"eta_i": 3.5}, r"`eta_i` must lie in \[1, 3\], got 3.5"),
            ({"eta_i": float("nan")}, r"`eta_i` must lie in \[1, 3\], got nan"),
            ({"compare": "schlick"}, r"`compare` must be one of none, lazanyi, reference"),
            ({"environment": "beach"}, r"`environment` must be one of white_sky, studio, outdoor"),
            ({"compare": "reference", "nk": None}, r"`nk` is needed for compare='reference'"),
        ],
    )
    def test_bad_input_raises_value_error(self, renderer, gold, nk, kwargs, message):
        arguments = {"nk": nk, "eta_i": 1.5, "size": 64, **kwargs}
        with pytest.raises(ValueError, match=message):
            renderer.render_preview(gold, **arguments)

    def test_not_a_packed_material(self, renderer):
        with pytest.raises(ValueError, match="`packed` must be a PackedMaterial"):
            renderer.render_preview({"name": "Au"}, None)


class TestCommandLine:
    def _run(self, *args):
        return run_command("preview_shaders", "render", *args, timeout=120)

    def test_fit_file_renders_the_golden(self, tmp_path):
        pack = tmp_path / "gold.cfpk"
        pack.write_bytes(encode_pack(pack_from_json((GOLDEN / "Au_golden.json").read_text())))
        out = tmp_path / "out.png"
        eta_i, size, compare, environment = CASES["preview_Au_lazanyi_2.5"]
        run = self._run(
            "--fit",
            str(pack),
            "--eta-i",
            str(eta_i),
            "--size",
            str(size),
            "--compare",
            compare,
            "--environment",
            environment,
            "-o",
            str(out),
        )
        assert run.returncode == 0, run.stderr
        np.testing.assert_array_equal(
            np.asarray(Image.open(out).convert("RGB")),
            np.asarray(Image.open(GOLDEN / "preview_Au_lazanyi_2.5.png").convert("RGB")),
        )

    def test_bad_size_is_an_error(self, tmp_path):
        run = self._run("--fit", str(GOLDEN / "Au_golden.json"), "--size", "4096", "-o", str(tmp_path / "x.png"))
        assert run.returncode == 2
        assert "`size` must lie in [64, 2048], got 4096" in run.stderr
        assert not (tmp_path / "x.png").exists()
