"""
The numpy mirrors of each tool's layering (fitting.exports.tool_layering)
against the tool's own render of the export, at roughness 0 under a uniform
white environment: MaterialX's generated GLSL (``mtlx``, ``openpbr``) on the
project's EGL context (preview_shaders.materialx_render).

Compared at the pixels of the sphere whose cos theta is near each tested
view angle (the mirror evaluated at each pixel's own cos theta), in Delta E
2000 (linear Rec.709 to ACEScg): the issue's bound, 0.2.
"""

from __future__ import annotations

import numpy as np
import pytest

from fitting.colour.delta_e import delta_E_map
from fitting.exports import export_material, export_values
from fitting.exports.colour_space import lin_rec709_to_ACEScg
from fitting.exports.tool_layering import tool_seen
from fitting.optics.library import library_material
from preview_shaders.materialx_render import render_materialx
from preview_shaders.preview import sphere_cos_theta

SIZE = 96
ANGLES_DEG = (0.0, 20.0, 40.0, 60.0, 70.0)
BOUND = 0.2  # the promise for a mirror against its tool
CASES = [("Cu", 1.5), ("Au", 2.0), ("Cr", 1.0)]


def pixels_at(mu: np.ndarray, mask: np.ndarray, angle: float) -> np.ndarray:
    """The sphere's pixels within 1 degree of ``angle``."""
    theta = np.degrees(np.arccos(np.clip(mu, 0.0, 1.0)))
    return mask & (np.abs(theta - angle) <= 1.0)


@pytest.fixture(scope="module")
def materialx_renders():
    from preview_shaders.gl import RenderThread

    out = {}
    with RenderThread("materialx-mirrors") as thread:
        for name, eta in CASES:
            values = export_values(library_material(name), eta, roughness=0.0, coat_roughness=0.0,
                                   tools=("mtlx", "openpbr"))
            for fmt in ("mtlx", "openpbr"):
                image, _ = render_materialx(export_material(values, fmt, eta).decode(), SIZE, thread)
                out[name, eta, fmt] = (values, image.astype(np.float64))
    return out


@pytest.mark.slow  # 6 GLSL renders
@pytest.mark.gl
@pytest.mark.numeric
@pytest.mark.parametrize("fmt", ["mtlx", "openpbr"])
def test_materialx_mirror_is_the_render(materialx_renders, fmt):
    mu, mask = sphere_cos_theta(SIZE)
    worst = 0.0
    for name, eta in CASES:
        values, image = materialx_renders[name, eta, fmt]
        for angle in ANGLES_DEG:
            at = pixels_at(mu, mask, angle)
            assert at.sum() >= 1
            mirror = tool_seen(fmt, values.tools[fmt], mu[at], eta)
            dE = delta_E_map(lin_rec709_to_ACEScg(image[at]), lin_rec709_to_ACEScg(mirror))
            worst = max(worst, float(dE.max()))
            assert dE.max() < BOUND, (name, eta, fmt, angle, dE.max())
    print(f"{fmt}: worst Delta E {worst:.4f}")
