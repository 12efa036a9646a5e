"""The preview sphere of an rgb-conductor: the shader's own kind, close to the spectral reference."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.fits.material import fit_material
from fitting.fits.rgb_conductor import fit_rgb_conductor
from fitting.models.rgb_conductor import rgb_conductor_model
from fitting.optics.library import library_material
from preview_shaders.preview import PreviewRenderer

pytestmark = [pytest.mark.gl, pytest.mark.numeric]


@pytest.fixture(scope="module")
def renderer():
    with PreviewRenderer() as active:
        yield active


def test_rgb_conductor_preview_against_reference(renderer):
    nk = library_material("Au")
    rgb = fit_rgb_conductor(nk, mu_samples=8, eta_samples=3).packed
    coated = fit_material(nk).packed
    ours = renderer.render_preview(rgb, nk, eta_i=1.5, size=64, compare="reference")
    paper = renderer.render_preview(coated, nk, eta_i=1.5, size=64, compare="reference")
    assert ours.png[:8] == b"\x89PNG\r\n\x1a\n"
    assert ours.delta_E_mean < paper.delta_E_mean
    # The left half is the kind's Fresnel times the environment, pixel by pixel.
    mask = ours.mask[:, :32]
    expected = (
        rgb_conductor_model(ours.cos_theta[:, :32][mask].astype(np.float64), 1.5, rgb.coefficients.astype(np.float64))
        * ours.radiance[:, :32][mask]
    )
    # The exact rgb-conductor Fresnel in float32 GLSL: its cancelling
    # 1 - sin^2 term near the critical angle (as in test_hard_cases' 1e-4:
    # 6e-5 at the closest pixel) times the radiance; not the smooth model's 1e-5.
    assert np.abs(ours.model[:, :32][mask] - expected).max() < 1e-4
