"""
The numpy mirrors of each tool's layering (fitting.exports.tool_layering)
against the tool's own render of the export, at roughness 0 under a uniform
white environment: MaterialX's generated GLSL (``mtlx``, ``openpbr``) on the
project's EGL context (preview_shaders.materialx_render); Cycles (Blender's
bpy, ``blender``, ``blender-conductor``) on a flat plane (cycles_angles.py).

Compared at the pixels of the sphere whose cos theta is near each tested
view angle (the mirror evaluated at each pixel's own cos theta), in Delta E
2000 (linear Rec.709 to ACEScg): the issue's bound, 0.2.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

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
            values = export_values(
                library_material(name), eta, roughness=0.0, coat_roughness=0.0, tools=("mtlx", "openpbr")
            )
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


# Cycles (Blender 5 as the bpy module, .venv-blender, one process per export
# and output): a flat plane seen at each angle under a white world, 128
# samples of 16 pixels (tests/fitting/exports/cycles_angles.py).
ROOT = Path(__file__).resolve().parents[3]
BLENDER_PYTHON = ROOT / ".venv-blender" / "bin" / "python"
CYCLES_ANGLES = (0.0, 40.0, 70.0)
CYCLES_CASES = [("Cu", 1.5), ("Cr", 1.0)]
CYCLES_OUTPUTS = {"principled": "blender", "conductor": "blender-conductor"}


@pytest.fixture(scope="module")
def cycles_renders(tmp_path_factory):
    assert BLENDER_PYTHON.exists(), "the Blender environment is missing: run scripts/bootstrap"
    tmp = tmp_path_factory.mktemp("cycles")
    out = {}
    for name, eta in CYCLES_CASES:
        values = export_values(
            library_material(name), eta, roughness=0.0, coat_roughness=0.0, tools=("blender", "blender-conductor")
        )
        script = tmp / f"{name}.py"
        script.write_bytes(export_material(values, "blender", eta))
        for output in CYCLES_OUTPUTS:
            result = subprocess.run(
                [
                    str(BLENDER_PYTHON),
                    str(Path(__file__).with_name("cycles_angles.py")),
                    str(script),
                    "--output",
                    output,
                    "--angles",
                    ",".join(f"{a:g}" for a in CYCLES_ANGLES),
                    "--samples",
                    "128",
                ],
                capture_output=True,
                text=True,
                timeout=600,
                cwd=tmp,
            )
            assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
            line = [ln for ln in result.stdout.splitlines() if ln.startswith("CYCLES_ANGLES ")][-1]
            out[name, eta, output] = (values, json.loads(line.split(" ", 1)[1]))
    return out


@pytest.mark.slow  # 4 Blender processes, ~12 s each
@pytest.mark.numeric
@pytest.mark.parametrize("output", list(CYCLES_OUTPUTS))
def test_cycles_mirror_is_the_render(cycles_renders, output):
    tool = CYCLES_OUTPUTS[output]
    for name, eta in CYCLES_CASES:
        values, rendered = cycles_renders[name, eta, output]
        mu = np.cos(np.radians(CYCLES_ANGLES))
        render = np.array([rendered[f"{a:g}"] for a in CYCLES_ANGLES])
        mirror = tool_seen(tool, values.tools[tool], mu, eta)
        dE = delta_E_map(lin_rec709_to_ACEScg(render), lin_rec709_to_ACEScg(mirror))
        assert dE.max() < BOUND, (name, eta, output, dE)
        print(f"{output} {name} {eta}: Delta E {np.round(dE, 4)}")
