"""
The glTF fallback (fitting.exports.gltf_fallback): the clear coat kept
wherever the physical coat is visible, and the values fitted at the metal's
roughness no worse there than the smooth fit.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fitting.exports import export_material, export_values
from fitting.exports.gltf_fallback import (
    VISIBLE_CLEARCOAT, coat_F0, gltf_clearcoat_floor, gltf_seen_delta_E, rough_seen_ACEScg,
)
from fitting.exports.seen_fit import fit_tool_values
from fitting.optics.library import library_material

pytestmark = pytest.mark.numeric
ROUGH = 0.3


def test_the_rule_bounds_where_the_coat_reflects_two_percent():
    assert coat_F0(1.33) >= 0.02 > coat_F0(1.32)
    for eta in (1.33, 1.5, 2.0, 3.0):
        assert gltf_clearcoat_floor(eta) == VISIBLE_CLEARCOAT == 0.5
    for eta in (1.0, 1.1, 1.32):
        assert gltf_clearcoat_floor(eta) == 0.0
    assert gltf_clearcoat_floor(1.5, coat=False) == 0.0


@pytest.mark.parametrize("name, eta", [("Cu", 1.33), ("Au", 1.5), ("W", 2.0), ("CuZn", 1.5)])
def test_the_coat_is_kept_and_the_rough_fit_no_worse_at_its_roughness(name, eta):
    values = export_values(library_material(name), eta, roughness=ROUGH, coat_roughness=0.0, tools=("gltf",))
    fitted = values.tools["gltf"]
    assert fitted["clearcoat"] >= 0.5
    # The fit at roughness 0 keeps the coat too; the old free fit drops it for these metals.
    smooth = fit_tool_values("gltf", values.view_cos, eta, values.seen_ACEScg)
    assert smooth["clearcoat"] >= 0.5
    free = fit_tool_values("gltf", values.view_cos, eta, values.seen_ACEScg, keep_coat=False)
    assert free["clearcoat"] < 0.5
    # What a viewer without the plugin shows at the metal's roughness: the rough fit is
    # no worse there than the values fitted at roughness 0 (the export before).
    target = values.seen_rough_ACEScg
    rough_mean = gltf_seen_delta_E(fitted, values.view_cos, eta, target, ROUGH).mean()
    smooth_mean = gltf_seen_delta_E(smooth, values.view_cos, eta, target, ROUGH).mean()
    assert rough_mean <= smooth_mean + 1e-9
    # The document carries the kept factor and says what it is fitted to.
    asset = json.loads(export_material(values, "gltf", eta))
    material = asset["materials"][0]
    assert material["extensions"]["KHR_materials_clearcoat"]["clearcoatFactor"] >= 0.5
    assert material["pbrMetallicRoughness"]["roughnessFactor"] == pytest.approx(ROUGH)
    assert "at the metal's roughness 0.3" in material["extras"]["coated_fresnel"]["delta_E_2000_seen_at_roughness"]


def test_below_the_rule_the_factor_is_free():
    values = export_values(library_material("Cu"), 1.2, roughness=0.0, tools=("gltf",))
    assert values.seen_rough_ACEScg is None  # a smooth metal: fitted at roughness 0 only
    free = fit_tool_values("gltf", values.view_cos, 1.2, values.seen_ACEScg, keep_coat=False)
    assert values.tools["gltf"]["clearcoat"] == pytest.approx(free["clearcoat"], abs=1e-12)


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
