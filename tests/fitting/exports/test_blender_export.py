"""
The Blender export in the real tool: the script runs in Blender as a Python
module (``bpy``, in its own environment ``.venv-blender``, as a separate
process), builds the node tree with the intended values (read back from
Blender) and renders a small Cycles image of a sphere.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from fitting.exports import export_material, export_values
from fitting.exports.blender import NODE_NAMES
from fitting.optics.library import library_material

ROOT = Path(__file__).resolve().parents[3]
BLENDER_PYTHON = ROOT / ".venv-blender" / "bin" / "python"
PREVIEW = ROOT / "fitting" / "exports" / "blender_preview.py"
SIZE = 32


@pytest.fixture(scope="module")
def values():
    return export_values(library_material("Cu"), 1.6, roughness=0.3, coat_roughness=0.05)


def run_in_blender(values, tmp_path: Path, output: str) -> tuple[dict, np.ndarray]:
    assert BLENDER_PYTHON.exists(), "the Blender environment is missing: run scripts/bootstrap"
    script = tmp_path / "export.py"
    script.write_bytes(export_material(values, "blender", values.eta_i))
    read_back, png = tmp_path / "values.json", tmp_path / "sphere.png"
    result = subprocess.run(
        [
            str(BLENDER_PYTHON),
            str(PREVIEW),
            str(script),
            "--values",
            str(read_back),
            "--render",
            str(png),
            "--size",
            str(SIZE),
            "--samples",
            "4",
            "--output",
            output,
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    # No deprecated call for the pinned Blender (it warns `use_nodes` on 5.0).
    assert "deprecated" not in (result.stdout + result.stderr).lower(), result.stdout + result.stderr
    with Image.open(png) as image:
        pixels = np.asarray(image.convert("RGB"), dtype=np.float64)
    return json.loads(read_back.read_text()), pixels


def assert_rgb(actual, expected):
    # Blender stores float32: u32 = 6e-8 relative; 1e-6 (17 u32) allows a
    # float32 conversion on each side.
    np.testing.assert_allclose(actual[:3], expected, rtol=1e-6, atol=1e-6)


@pytest.fixture(scope="module")
def principled(values, tmp_path_factory):
    return run_in_blender(values, tmp_path_factory.mktemp("principled"), "principled")


@pytest.fixture(scope="module")
def conductor(values, tmp_path_factory):
    return run_in_blender(values, tmp_path_factory.mktemp("conductor"), "conductor")


class TestPrincipled:
    @pytest.mark.slow  # 4.4 s (all cases 4.4 s) in a --durations=0 run
    def test_node_values(self, values, principled):
        nodes = principled[0]["nodes"]
        node = nodes[NODE_NAMES["principled"]]
        assert node["type"] == "ShaderNodeBsdfPrincipled"
        inputs = node["inputs"]
        # The values fitted to the coated metal seen from air.
        assert_rgb(inputs["Base Color"], values.tools["blender"]["base_color"])
        assert_rgb(inputs["Specular Tint"], values.tools["blender"]["specular_tint"])
        assert inputs["Metallic"] == 1.0 and inputs["Coat Weight"] == 1.0
        # float32 storage, as assert_rgb.
        assert inputs["Coat IOR"] == pytest.approx(values.eta_i, rel=1e-6)
        assert inputs["Roughness"] == pytest.approx(0.3, rel=1e-6)
        assert inputs["Coat Roughness"] == pytest.approx(0.05, rel=1e-6)
        assert nodes[NODE_NAMES["output"]]["is_active_output"] is True
        assert nodes[NODE_NAMES["conductor_output"]]["is_active_output"] is False
        assert [NODE_NAMES["principled"], "BSDF", NODE_NAMES["output"], "Surface"] in principled[0]["links"]
        provenance = json.loads(principled[0]["custom"]["coated_fresnel"])
        assert provenance["material"] == "Cu" and provenance["eta_i"] == 1.6

    @pytest.mark.slow  # starts a process or GL context
    def test_render(self, principled):
        pixels = principled[1]
        assert pixels.shape == (SIZE, SIZE, 3)
        centre = pixels[SIZE // 2 - 2 : SIZE // 2 + 2, SIZE // 2 - 2 : SIZE // 2 + 2].mean(axis=(0, 1))
        # The sphere is there and copper-coloured (red over blue) where the
        # checkered environment is grey.
        assert centre[0] > centre[2] + 20, centre
        corner = pixels[:3, :3].reshape(-1, 3)
        assert np.all(np.abs(corner[:, 0] - corner[:, 2]) < 8), corner


class TestPhysicalConductor:
    @pytest.mark.slow  # 2.0 s (all cases 2.0 s) in a --durations=0 run
    def test_node_values(self, values, conductor):
        nodes = conductor[0]["nodes"]
        metallic = nodes[NODE_NAMES["metallic"]]
        assert metallic["type"] == "ShaderNodeBsdfMetallic"
        assert metallic["fresnel_type"] == "PHYSICAL_CONDUCTOR"
        fitted = values.tools["blender-conductor"]
        links = conductor[0]["links"]
        for socket, key in (("IOR", "ior"), ("Extinction", "extinction")):
            if not np.any(fitted[f"{key}_per_facing"]):
                assert_rgb(metallic["inputs"][socket], fitted[key])
                continue
            # max(slope * Facing + constant, lower bound) into the socket, Facing = 1 - cos theta.
            affine, bound = nodes[NODE_NAMES[f"{key}_affine"]], nodes[NODE_NAMES[f"{key}_bound"]]
            assert (affine["operation"], bound["operation"]) == ("MULTIPLY_ADD", "MAXIMUM")
            assert_rgb(affine["inputs"]["Vector"], fitted[f"{key}_per_facing"])
            assert_rgb(affine["inputs"]["Vector_002"], fitted[key])
            assert_rgb(bound["inputs"]["Vector"], [{"ior": 1e-3, "extinction": 0.0}[key]] * 3)
            assert [NODE_NAMES["facing"], "Facing", NODE_NAMES[f"{key}_affine"], "Vector_001"] in links
            assert [NODE_NAMES[f"{key}_affine"], "Vector", NODE_NAMES[f"{key}_bound"], "Vector"] in links
            assert [NODE_NAMES[f"{key}_bound"], "Vector", NODE_NAMES["metallic"], socket] in links
        if np.any(fitted["ior_per_facing"]) or np.any(fitted["extinction_per_facing"]):
            assert nodes[NODE_NAMES["facing"]]["inputs"]["Blend"] == 0.5
        else:
            assert NODE_NAMES["facing"] not in nodes
        assert nodes[NODE_NAMES["coat_fresnel"]]["inputs"]["IOR"] == pytest.approx(
            1.6, rel=1e-6
        )  # float32, as assert_rgb
        assert nodes[NODE_NAMES["conductor_output"]]["is_active_output"] is True
        assert nodes[NODE_NAMES["output"]]["is_active_output"] is False
        assert [NODE_NAMES["coat_mix"], "Shader", NODE_NAMES["conductor_output"], "Surface"] in links
        assert [NODE_NAMES["coat_fresnel"], "Factor", NODE_NAMES["coat_mix"], "Fac"] in links

    @pytest.mark.slow  # starts a process or GL context
    def test_render(self, conductor):
        pixels = conductor[1]
        centre = pixels[SIZE // 2 - 2 : SIZE // 2 + 2, SIZE // 2 - 2 : SIZE // 2 + 2].mean(axis=(0, 1))
        assert centre[0] > centre[2] + 20, centre
