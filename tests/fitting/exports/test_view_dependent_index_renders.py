"""
The conductor exports' index driven by the view angle, rendered by the tools
(docs/exports.md "A better form each tool offers"): for W and CuZn
at eta_i 1.5 the shipped `mtlx` document and Blender script carry each
channel's n and k affine in 1 - cos theta (a `normal` / `viewdirection`
graph into `conductor_bsdf`; Layer Weight's Facing into the Metallic BSDF),
and MaterialX's GLSL and Cycles render the exports as written, unchanged,
as the numpy mirror (fitting.exports.tool_layering.tool_seen of the
exported values) says, within the issue's 0.2 Delta E, at roughness 0.
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

ROOT = Path(__file__).resolve().parents[3]
BLENDER_PYTHON = ROOT / ".venv-blender" / "bin" / "python"
BOUND = 0.2  # the promise for a mirror against its tool
ETA = 1.5
METALS = ("W", "CuZn")  # the two the constant index left over 1.0


def shipped(name: str, tools: tuple[str, ...], tool: str):
    values = export_values(library_material(name), ETA, roughness=0.0, coat_roughness=0.0, tools=tools)
    fitted = values.tools[tool]
    # The exports carry the graph: the fit found slopes (else this tests constants).
    assert np.any(fitted["ior_per_facing"]) or np.any(fitted["extinction_per_facing"]), (name, tool)
    return values, fitted


@pytest.mark.slow  # 2 GLSL renders
@pytest.mark.gl
@pytest.mark.numeric
def test_materialx_renders_the_shipped_view_dependent_index():
    from preview_shaders.materialx_render import render_materialx
    from preview_shaders.preview import sphere_cos_theta

    size = 96
    mu, mask = sphere_cos_theta(size)
    theta = np.degrees(np.arccos(np.clip(mu, 0.0, 1.0)))
    for name in METALS:
        values, fitted = shipped(name, ("mtlx",), "mtlx")
        document = export_material(values, "mtlx", ETA).decode()
        assert "viewdirection" in document
        image, _ = render_materialx(document, size)
        for angle in (0.0, 20.0, 40.0, 60.0, 70.0):
            at = mask & (np.abs(theta - angle) <= 1.0)
            dE = delta_E_map(
                lin_rec709_to_ACEScg(image[at].astype(np.float64)),
                lin_rec709_to_ACEScg(tool_seen("mtlx", fitted, mu[at], ETA)),
            )
            assert dE.max() < BOUND, (name, angle, dE.max())


@pytest.mark.slow  # 2 Blender processes, ~5 s each
@pytest.mark.numeric
def test_cycles_renders_the_shipped_view_dependent_index(tmp_path):
    assert BLENDER_PYTHON.exists(), "the Blender environment is missing: run scripts/bootstrap"
    angles = (0.0, 40.0, 70.0, 80.0)
    for name in METALS:
        values, fitted = shipped(name, ("blender", "blender-conductor"), "blender-conductor")
        script = tmp_path / f"{name}.py"
        script.write_text(export_material(values, "blender", ETA).decode())
        result = subprocess.run(
            [
                str(BLENDER_PYTHON),
                str(Path(__file__).with_name("cycles_angles.py")),
                str(script),
                "--output",
                "conductor",
                "--angles",
                ",".join(f"{a:g}" for a in angles),
                "--samples",
                "128",
            ],
            capture_output=True,
            text=True,
            timeout=600,
            cwd=tmp_path,
        )
        assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
        assert "deprecated" not in (result.stdout + result.stderr).lower()
        line = [ln for ln in result.stdout.splitlines() if ln.startswith("CYCLES_ANGLES ")][-1]
        rendered = json.loads(line.split(" ", 1)[1])
        render = np.array([rendered[f"{a:g}"] for a in angles])
        dE = delta_E_map(
            lin_rec709_to_ACEScg(render),
            lin_rec709_to_ACEScg(tool_seen("blender-conductor", fitted, np.cos(np.radians(angles)), ETA)),
        )
        assert dE.max() < BOUND, (name, dE)
