"""
The glTF fallback (fitting.exports.gltf_fallback): the clear coat whole
wherever there is a coat (its factor is the coat's, which the extension
composes with), and the base colour fitted at the metal's roughness no worse
there than the smooth fit.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fitting.exports import export_material, export_values
from fitting.exports.gltf_fallback import (
    GLTF_COAT_FACTOR,
    VISIBLE_COAT_F0,
    coat_F0,
    gltf_seen_delta_E,
    rough_seen_ACEScg,
)
from fitting.exports.seen_fit import fit_tool_values
from fitting.optics.library import library_material

pytestmark = pytest.mark.numeric
ROUGH = 0.3


def test_the_visible_coat_starts_at_two_percent_and_every_coat_is_whole():
    assert coat_F0(1.33) >= VISIBLE_COAT_F0 > coat_F0(1.32)
    # A coat reflecting less than 2 % is whole too (its factor is the coat's, not a fit's).
    values = export_values(library_material("Cu"), 1.2, roughness=0.0, tools=("gltf",))
    assert values.tools["gltf"]["clearcoat"] == 1.0


@pytest.mark.parametrize("name, eta", [("Cu", 1.33), ("Au", 1.5), ("W", 2.0), ("CuZn", 1.5)])
def test_the_coat_is_whole_and_the_rough_fit_no_worse_at_its_roughness(name, eta):
    values = export_values(library_material(name), eta, roughness=ROUGH, coat_roughness=0.0, tools=("gltf",))
    fitted = values.tools["gltf"]
    # The coat's own factor, which the extension composes with: whole wherever there is a coat.
    assert fitted["clearcoat"] == GLTF_COAT_FACTOR == 1.0
    smooth = fit_tool_values("gltf", values.view_cos, eta, values.seen_ACEScg)
    assert smooth["clearcoat"] == 1.0
    # The factor fitted too (the export before) drops the coat for these metals.
    free = fit_tool_values("gltf", values.view_cos, eta, values.seen_ACEScg, keep_coat=False)
    assert free["clearcoat"] < 0.5
    # What a viewer without the plugin shows at the metal's roughness: the rough fit is
    # no worse there than the values fitted at roughness 0.
    target = values.seen_rough_ACEScg
    rough_mean = gltf_seen_delta_E(fitted, values.view_cos, eta, target, ROUGH).mean()
    smooth_mean = gltf_seen_delta_E(smooth, values.view_cos, eta, target, ROUGH).mean()
    assert rough_mean <= smooth_mean + 1e-9
    # The document carries the coat and says what the base colour is fitted to.
    asset = json.loads(export_material(values, "gltf", eta))
    material = asset["materials"][0]
    assert material["extensions"]["KHR_materials_clearcoat"]["clearcoatFactor"] == 1.0
    assert material["pbrMetallicRoughness"]["roughnessFactor"] == pytest.approx(ROUGH)
    assert "at the metal's roughness 0.3" in material["extras"]["coated_fresnel"]["delta_E_2000_seen_at_roughness"]


def test_the_rough_target():
    values = export_values(library_material("Ag"), 1.5, roughness=0.0, tools=())
    args = (values.view_cos, 1.5, values.seen_ACEScg, values.cos_theta, values.target_ACEScg)
    np.testing.assert_array_equal(rough_seen_ACEScg(*args, 0.0), values.seen_ACEScg)
    nodes, every = rough_seen_ACEScg(*args, ROUGH), rough_seen_ACEScg(*args, ROUGH, rough_nodes=None)
    np.testing.assert_allclose(nodes, every, atol=2e-3)
    # A rough metal under a coat is darker than the mirror: light scattered past the
    # critical angle stays in the coat and meets the metal again.
    assert np.all(every[:, 1] < values.seen_ACEScg[:, 1])
    assert np.all(np.isfinite(every)) and np.all(every >= 0.0)
