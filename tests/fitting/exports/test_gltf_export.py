"""
The glTF export in the real tools: the Khronos glTF validator (npm package
``gltf-validator``, installed by scripts/bootstrap under
scripts/gltf-validator/) reports no error and no warning, and ``pygltflib``
reads the intended material back.
"""

from __future__ import annotations

import base64
import json
import subprocess
from pathlib import Path

import numpy as np
import pygltflib
import pytest

from fitting.exports import export_material, export_values
from fitting.exports.gltf import uv_sphere
from fitting.optics.library import library_material

ROOT = Path(__file__).resolve().parents[3]
VALIDATOR = ROOT / "scripts" / "gltf-validator"


def khronos_report(path: Path) -> tuple[int, dict]:
    assert (VALIDATOR / "node_modules" / "gltf-validator").is_dir(), (
        "gltf-validator is not installed: run scripts/bootstrap"
    )
    result = subprocess.run(
        ["node", str(VALIDATOR / "validate.mjs"), str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    return result.returncode, json.loads(result.stdout)


@pytest.fixture(scope="module", params=[1.5, 2.2], ids=["eta1.5", "eta2.2"])
def exported(request, tmp_path_factory):
    values = export_values(library_material("Au"), request.param, roughness=0.35)
    path = tmp_path_factory.mktemp("gltf") / "au.gltf"
    path.write_bytes(export_material(values, "gltf", values.eta_i))
    return values, path


class TestKhronosValidator:
    @pytest.mark.slow  # starts a process or GL context
    def test_no_errors_no_warnings(self, exported):
        _, path = exported
        code, report = khronos_report(path)
        assert code == 0, report["issues"]
        assert report["issues"]["numErrors"] == 0 and report["issues"]["numWarnings"] == 0, report
        # The coat's index in the draft KHR_materials_clearcoat_ior (an information: the validator does not know it).
        assert report["info"]["extensionsUsed"] == ["KHR_materials_clearcoat", "KHR_materials_clearcoat_ior"]
        assert {m["code"] for m in report["issues"]["messages"]} <= {"UNSUPPORTED_EXTENSION"}
        assert report["info"]["materialCount"] == 1 and report["info"]["drawCallCount"] == 1

    @pytest.mark.slow  # starts a process or GL context
    def test_validator_catches_a_broken_asset(self, exported, tmp_path):
        _, path = exported
        asset = json.loads(path.read_text())
        asset["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = 2.0
        del asset["accessors"][0]["max"]
        broken = tmp_path / "broken.gltf"
        broken.write_text(json.dumps(asset))
        code, report = khronos_report(broken)
        assert code == 1 and report["issues"]["numErrors"] >= 2
        codes = {m["code"] for m in report["issues"]["messages"]}
        assert "VALUE_NOT_IN_RANGE" in codes and "MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS" in codes


class TestRoundTrip:
    def test_material_values(self, exported):
        values, path = exported
        gltf = pygltflib.GLTF2().load(str(path))
        (material,) = gltf.materials
        pbr = material.pbrMetallicRoughness
        # Written as float32 (glTF's component type): u32 = 6e-8 of values <= 1;
        # 1e-6 allows a conversion on each side (approx's default rel=1e-6 below
        # likewise, 17 u32).
        np.testing.assert_allclose(pbr.baseColorFactor[:3], values.tools["gltf"]["base_color"], atol=1e-6)
        assert pbr.baseColorFactor[3] == 1.0 and pbr.metallicFactor == 1.0
        assert pbr.roughnessFactor == pytest.approx(0.35)
        coat = material.extensions["KHR_materials_clearcoat"]
        assert coat["clearcoatFactor"] == values.tools["gltf"]["clearcoat"] == 1.0  # the coat, whole
        assert coat["clearcoatRoughnessFactor"] == pytest.approx(values.coat_roughness)
        assert coat["extensions"]["KHR_materials_clearcoat_ior"]["clearcoatIor"] == values.eta_i
        provenance = material.extras["coated_fresnel"]
        assert provenance["material"] == "Au" and provenance["eta_i"] == values.eta_i
        assert ("note" in provenance) == (values.eta_i != 1.5)

    def test_sphere_buffer(self, exported):
        _, path = exported
        gltf = pygltflib.GLTF2().load(str(path))
        data = base64.b64decode(gltf.buffers[0].uri.split(",", 1)[1])
        assert len(data) == gltf.buffers[0].byteLength
        view = gltf.bufferViews[gltf.accessors[0].bufferView]
        positions = np.frombuffer(data, np.float32, gltf.accessors[0].count * 3, view.byteOffset)
        np.testing.assert_allclose(np.linalg.norm(positions.reshape(-1, 3), axis=1), 1.0, atol=1e-6)  # float32
        # unit vectors: 3 coordinates each within u32: the norm within ~3 u32 = 2e-7

    def test_sphere_faces_outward(self):
        positions, _, indices = uv_sphere()
        a, b, c = (positions[indices.reshape(-1, 3)[:, i]].astype(np.float64) for i in range(3))
        normal = np.cross(b - a, c - a)
        assert np.all(np.einsum("ij,ij->i", normal, a + b + c) > 0)


class TestBlenderImport:
    """Blender's bundled glTF importer reads the asset and Cycles renders it."""

    @pytest.mark.slow  # 3.6 s (all cases 6.6 s) in a --durations=0 run
    def test_import_and_render(self, exported, tmp_path):
        values, path = exported
        blender_python = ROOT / ".venv-blender" / "bin" / "python"
        assert blender_python.exists(), "the Blender environment is missing: run scripts/bootstrap"
        read_back, png = tmp_path / "values.json", tmp_path / "sphere.png"
        result = subprocess.run(
            [
                str(blender_python),
                str(ROOT / "fitting" / "exports" / "blender_preview.py"),
                str(path),
                "--gltf",
                "--values",
                str(read_back),
                "--render",
                str(png),
                "--size",
                "24",
                "--samples",
                "2",
            ],
            capture_output=True,
            text=True,
            timeout=300,
            cwd=tmp_path,
        )
        assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
        material = json.loads(read_back.read_text())
        (principled,) = [n for n in material["nodes"].values() if n["type"] == "ShaderNodeBsdfPrincipled"]
        inputs = principled["inputs"]
        np.testing.assert_allclose(
            inputs["Base Color"][:3], values.tools["gltf"]["base_color"], atol=1e-6
        )  # float32, as above
        assert inputs["Metallic"] == 1.0
        # The coat's clearcoatFactor (1), float32 as above.
        assert inputs["Coat Weight"] == pytest.approx(values.tools["gltf"]["clearcoat"], abs=1e-6)
        # glTF's clear coat has index 1.5 whatever the export was fitted for.
        assert inputs["Coat IOR"] == pytest.approx(1.5)
        assert material["custom"]["coated_fresnel"]["eta_i"] == values.eta_i
        assert png.stat().st_size > 0


class TestGLB:
    """The same asset as binary glTF (``.glb``), beside the ``.gltf``."""

    @pytest.mark.slow  # starts a process
    def test_validates_and_is_the_gltf(self, exported, tmp_path):
        values, path = exported
        glb = tmp_path / "au.glb"
        glb.write_bytes(export_material(values, "glb", values.eta_i))
        code, report = khronos_report(glb)
        assert code == 0, report["issues"]
        assert report["issues"]["numErrors"] == 0 and report["issues"]["numWarnings"] == 0, report
        assert report["info"]["materialCount"] == 1 and report["info"]["drawCallCount"] == 1
        binary, text = pygltflib.GLTF2().load(str(glb)), json.loads(path.read_text())
        material, expected = binary.materials[0], text["materials"][0]
        assert material.name == expected["name"] and material.extras == expected["extras"]
        assert material.extensions == expected["extensions"]
        assert material.pbrMetallicRoughness.baseColorFactor == expected["pbrMetallicRoughness"]["baseColorFactor"]
        # The same buffer: the .gltf's data URI, the .glb's BIN chunk.
        uri = text["buffers"][0]["uri"].split(",", 1)[1]
        assert binary.binary_blob()[: text["buffers"][0]["byteLength"]] == base64.b64decode(uri)
