"""
The conductor exports' index driven by the view angle: the fit
(fitting.exports.seen_fit.fit_view_dependent_index) lowers W below 1.0 in
both conductor tools, falls back to the constant fit (slopes 0) where it
does not help, keeps n and k inside the fit's bounds at every angle, and the
writers emit the graph only for non-zero slopes. The tools' renders of it:
test_view_dependent_index_renders.py.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fitting.colour.seen import SEEN_ANGLES_DEG, seen_ACEScg
from fitting.exports import export_material, export_values
from fitting.exports.colour_space import lin_rec709_to_ACEScg
from fitting.exports.seen_fit import (
    K_BOUNDS,
    N_BOUNDS,
    fit_tool_values,
    fit_view_dependent_index,
    seen_delta_E,
)
from fitting.exports.tool_layering import conductor_index, tool_seen
from fitting.optics.library import library_material

pytestmark = pytest.mark.numeric
MU = np.cos(np.radians(SEEN_ANGLES_DEG))
CONDUCTORS = ("mtlx", "blender-conductor")


@pytest.fixture(scope="module")
def w_target():
    return seen_ACEScg(library_material("W"), MU, 1.5)


@pytest.mark.slow  # the seen target and two fits: 1-3 s
@pytest.mark.parametrize("tool", CONDUCTORS)
def test_fit_takes_w_below_one(tool, w_target):
    constant = fit_tool_values(tool, MU, 1.5, w_target, view_dependent=False)
    shipped = fit_tool_values(tool, MU, 1.5, w_target)
    before = seen_delta_E(tool, constant, MU, 1.5, w_target).mean()
    after = seen_delta_E(tool, shipped, MU, 1.5, w_target).mean()
    # Measured: mtlx 1.158 -> 0.929, Physical Conductor 1.051 -> 0.919.
    assert before > 1.0 and after < 1.0, (before, after)
    assert np.any(shipped["ior_per_facing"]) or np.any(shipped["extinction_per_facing"])
    # n, k inside the fit's bounds at every angle (the values at facing 0 and 1 are).
    for facing in (0.0, 1.0):
        n = shipped["ior"] + shipped["ior_per_facing"] * facing
        k = shipped["extinction"] + shipped["extinction_per_facing"] * facing
        assert np.all((n >= N_BOUNDS[0] - 1e-12) & (n <= N_BOUNDS[1] + 1e-12)), n
        assert np.all((k >= K_BOUNDS[0] - 1e-12) & (k <= K_BOUNDS[1] + 1e-12)), k
    assert set(constant) == {"ior", "extinction", "coat"}


@pytest.mark.parametrize("tool", CONDUCTORS)
def test_falls_back_to_the_constants_with_slopes_zero(tool):
    # A target a constant index meets exactly: no slope can do better.
    constant = {"ior": np.array([0.3, 0.6, 1.1]), "extinction": np.array([3.0, 2.6, 2.4]), "coat": True}
    target = lin_rec709_to_ACEScg(tool_seen(tool, constant, MU, 1.5))
    fitted = fit_view_dependent_index(tool, MU, 1.5, target, constant)
    assert np.array_equal(fitted["ior"], constant["ior"])
    assert np.array_equal(fitted["extinction"], constant["extinction"])
    assert not np.any(fitted["ior_per_facing"]) and not np.any(fitted["extinction_per_facing"])
    # Slopes 0: the mirror is the constant index's.
    np.testing.assert_array_equal(tool_seen(tool, fitted, MU, 1.5), tool_seen(tool, constant, MU, 1.5))


def test_index_at_least_the_lower_bounds():
    values = {
        "ior": np.full(3, 0.5),
        "ior_per_facing": np.array([-1.0, 0.0, 1.0]),
        "extinction": np.full(3, 1.0),
        "extinction_per_facing": np.array([-2.0, 0.0, 2.0]),
    }
    n, k = conductor_index(values, MU)
    assert n.shape == k.shape == (MU.size, 3)
    assert n[:, 0].min() == N_BOUNDS[0] and k[:, 0].min() == K_BOUNDS[0]
    np.testing.assert_allclose(n[:, 2], 0.5 + (1.0 - MU))
    np.testing.assert_allclose(k[:, 1], 1.0)
    # Without slopes: the constants.
    n, k = conductor_index({"ior": values["ior"], "extinction": values["extinction"]}, MU)
    assert n.shape == (3,) and np.array_equal(k, values["extinction"])


@pytest.mark.slow  # the seen fits: 2 s
def test_writers_emit_the_graph_only_for_slopes():
    values = export_values(library_material("W"), 1.5, tools=CONDUCTORS + ("blender",))
    for tool in CONDUCTORS:
        assert np.any(values.tools[tool]["ior_per_facing"]), tool
    mtlx = export_material(values, "mtlx", 1.5).decode()
    script = export_material(values, "blender", 1.5).decode()
    for part in ("<viewdirection", "<normal", "<dotproduct", 'nodename="ior_at_view"', 'nodename="extinction_at_view"'):
        assert part in mtlx, part
    assert "ShaderNodeLayerWeight" in script and "CONDUCTOR_IOR_PER_FACING = (0.0, 0.0, 0.0)" not in script
    flat = {
        tool: {**values.tools[tool], "ior_per_facing": np.zeros(3), "extinction_per_facing": np.zeros(3)}
        for tool in CONDUCTORS
    }
    constant = dataclasses.replace(values, tools={**values.tools, **flat})
    mtlx = export_material(constant, "mtlx", 1.5).decode()
    script = export_material(constant, "blender", 1.5).decode()
    assert "<viewdirection" not in mtlx and 'name="ior" type="color3" value=' in mtlx
    assert "CONDUCTOR_IOR_PER_FACING = (0.0, 0.0, 0.0)" in script
    assert "CONDUCTOR_EXTINCTION_PER_FACING = (0.0, 0.0, 0.0)" in script
