"""
Exports in a working space: the MaterialX documents declare theirs (on the
document and on the conductor's n, k) so that MaterialX's own colour
management leaves a matching host's values alone; the Blender script reads
the file's working space (Blender 5) and refuses another, and run as a
script changes only the active material slot.
"""

from __future__ import annotations

import subprocess
import textwrap
from pathlib import Path

import MaterialX as mx
import numpy as np
import pytest

from fitting.exports import export_material, export_values
from fitting.exports.colour_space import ACEScg_to_working, check_working_space, working_to_ACEScg
from fitting.optics.library import library_material
from preview_shaders.materialx_render import materialx_glsl

ROOT = Path(__file__).resolve().parents[3]
BLENDER_PYTHON = ROOT / ".venv-blender" / "bin" / "python"


class TestSpaces:
    def test_round_trip(self):
        rgb = np.array([[0.9, 0.6, 0.2], [0.1, 0.5, 0.8]])
        for space in ("lin_rec709", "acescg"):
            np.testing.assert_allclose(working_to_ACEScg(ACEScg_to_working(rgb, space), space), rgb, atol=1e-12)
        np.testing.assert_array_equal(ACEScg_to_working(rgb, "acescg"), rgb)

    def test_bad_space(self):
        with pytest.raises(ValueError, match="`working_space` must be one of lin_rec709, acescg, got 'srgb'"):
            check_working_space("srgb")
        with pytest.raises(ValueError, match="`working_space`"):
            export_values(library_material("Au"), 1.5, tools=(), working_space="ACEScg")


@pytest.fixture(scope="module")
def au_values():
    """Gold at 1.5 fitted in each working space: (lin_rec709, acescg)."""
    return tuple(
        export_values(library_material("Au"), 1.5, working_space=space, tools=("mtlx", "blender", "blender-conductor"))
        for space in ("lin_rec709", "acescg")
    )


@pytest.mark.slow  # two export fits, about 6 s
class TestMaterialX:
    def test_declared_on_the_document_and_the_conductor(self, au_values):
        rec709, aces = au_values
        # Other values: a channel's n, k is another fit in another space.
        assert not np.allclose(rec709.tools["mtlx"]["ior"], aces.tools["mtlx"]["ior"], rtol=1e-3)
        doc = mx.createDocument()
        mx.readFromXmlString(doc, export_material(aces, "mtlx", 1.5).decode())
        assert doc.getColorSpace() == "acescg"
        (graph,) = doc.getNodeGraphs()
        values = [
            i for node in graph.getNodes() for i in node.getInputs() if i.getType() == "color3" and i.getValueString()
        ]
        assert values and {i.getColorSpace() for i in values} == {"acescg"}

    def test_matching_host_converts_nothing(self, au_values):
        # MaterialX's own colour management, target ACEScg (as an ACEScg host
        # generates the shader): no transform node for the acescg document;
        # the acescg document in a lin_rec709 host is converted (the check can fail).
        _, aces = au_values
        text = export_material(aces, "mtlx", 1.5).decode()
        _, pixel = materialx_glsl(text, target_colorspace="acescg")
        assert "acescg_to_lin_rec709" not in pixel
        _, converted = materialx_glsl(text, target_colorspace="lin_rec709")
        assert "acescg_to_lin_rec709" in converted


def run_blender(code: str, tmp_path: Path) -> subprocess.CompletedProcess:
    assert BLENDER_PYTHON.exists(), "the Blender environment is missing: run scripts/bootstrap"
    driver = tmp_path / "driver.py"
    driver.write_text(textwrap.dedent(code))
    return subprocess.run([str(BLENDER_PYTHON), str(driver)], capture_output=True, text=True, timeout=300, cwd=tmp_path)


@pytest.mark.slow  # starts Blender
def test_blender_refuses_another_working_space_and_touches_one_slot(au_values, tmp_path):
    rec709, aces = au_values
    (tmp_path / "rec709.py").write_bytes(export_material(rec709, "blender", 1.5))
    (tmp_path / "aces.py").write_bytes(export_material(aces, "blender", 1.5))
    result = run_blender(
        """
        import runpy, bpy
        bpy.ops.wm.read_factory_settings(use_empty=True)
        bpy.ops.mesh.primitive_cube_add()
        cube = bpy.context.active_object
        keep, old = bpy.data.materials.new("keep"), bpy.data.materials.new("old")
        cube.data.materials.append(keep)
        cube.data.materials.append(old)
        cube.active_material_index = 1
        runpy.run_path("rec709.py", run_name="__main__")
        names = [s.material.name for s in cube.material_slots]
        assert names[0] == "keep" and names[1].startswith("Au_") and names[1].endswith("_eta1p5"), names
        assert "old" in bpy.data.materials and len(bpy.data.materials) == 3
        made = cube.material_slots[1].material
        assert made["coated_fresnel_working_space"] == "lin_rec709" and made["coated_fresnel_eta_i"] == 1.5
        bpy.ops.wm.set_working_color_space(working_space="ACEScg", convert_colors=False)
        try:
            runpy.run_path("rec709.py", run_name="__main__")
        except RuntimeError as error:
            print("REFUSED", error)
        else:
            raise AssertionError("a Rec.709 export was built in an ACEScg file")
        assert len(bpy.data.materials) == 3
        runpy.run_path("aces.py", run_name="__main__")
        assert cube.material_slots[1].material["coated_fresnel_working_space"] == "acescg"
        print("OK")
    """,
        tmp_path,
    )
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "OK" in result.stdout
    assert (
        "REFUSED coated-fresnel: this file's working space is 'lin_ap1_scene', but this material's "
        "colours and n, k were fitted in 'lin_rec709'; export it again with working_space=acescg"
    ) in result.stdout


@pytest.mark.slow  # 16 export fits, about 15 s
def test_acescg_is_as_faithful_as_rec709_metal_by_metal():
    # What an ACEScg host sees of an ACEScg export is within 0.1 Delta E (mean
    # over the view angles) of what a Rec.709 host sees of a Rec.709 one, for
    # each of 8 metals and each tool; the numpy mirrors stand for the tools'
    # renders (test_tool_layering_renders.py, benchmarks/exports_working_space.py).
    from fitting.exports import seen_fidelity

    tools = ("mtlx", "openpbr", "blender", "blender-conductor")
    for metal in ("Au", "Cu", "Ag", "Al", "CuZn", "Cr", "Ni", "W"):
        rec709, aces = (
            export_values(
                library_material(metal), 1.5, roughness=0.0, coat_roughness=0.0, tools=tools, working_space=space
            )
            for space in ("lin_rec709", "acescg")
        )
        for tool in tools:
            worse = seen_fidelity(aces, tool)["delta_E_mean"] - seen_fidelity(rec709, tool)["delta_E_mean"]
            assert worse <= 0.1, (metal, tool, worse)
