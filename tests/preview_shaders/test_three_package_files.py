"""
The three.js package's generated modules (web/three/src/generated/, written
by ``python -m preview_shaders.three_package``): current with their sources
(the GLSL of preview_shaders/glsl/, the model kinds' registry and the
split-sum LUT), a stale or damaged one reported by the check, a kind
registered later carried by the kinds module, and the package's own decoder (web/three/src/lut.js,
run by node) giving back the LUT's float32 texels bit for bit.
"""

from __future__ import annotations

import json
import shutil
import subprocess

import numpy as np
import pytest

from fitting.models.kinds import MODEL_KINDS, ModelKind, register_model_kind, unregister_model_kind
from fitting.shading.lut import default_lut, encode_lut
from preview_shaders import three_package


def test_generated_files_are_current():
    assert three_package.stale() == [], "run .venv/bin/python -m preview_shaders.three_package"


def test_a_stale_or_damaged_file_is_reported(tmp_path, monkeypatch):
    for name in ("glsl.js", "lut.js", *three_package.KIND_FILES):
        (tmp_path / name).write_text((three_package.OUT / name).read_text())
    monkeypatch.setattr(three_package, "OUT", tmp_path)
    monkeypatch.setattr(three_package, "ROOT", tmp_path.parent)
    assert three_package.stale() == []
    glsl = (tmp_path / "glsl.js").read_text()
    (tmp_path / "glsl.js").write_text(glsl.replace("cf_fresnel_dielectric", "cf_fresnel_dielectric_old", 1))
    lut = three_package.read_lut_module((tmp_path / "lut.js").read_text())
    lut["alphaRange"] = [0.5, 11.0]
    (tmp_path / "lut.js").write_text(f"export const LUT = {json.dumps(lut)};\n")
    kinds = (tmp_path / "kinds.js").read_text()
    (tmp_path / "kinds.js").write_text(kinds.replace('"maxDegree": 2', '"maxDegree": 1', 1))
    assert sorted(three_package.stale()) == [f"{tmp_path.name}/{name}" for name in ("glsl.js", "kinds.js", "lut.js")]
    (tmp_path / "lut.js").write_text("export const LUT = {};\n")
    assert f"{tmp_path.name}/lut.js" in three_package.stale()


def _module_kinds(text: str) -> list[dict]:
    return json.loads(text.split("Object.freeze(", 1)[1].split(");\nexport const DEFAULT_KIND", 1)[0])


def test_a_kind_registered_later_is_packaged():
    """
    A kind given to the registry (a toy: Schlick of a constant F0 in
    [0, 1], from the shared cf_schlick) is in the generated kinds with its
    parameters, its sign rule as its check states it, its model function and
    model-row program, and in the types; the files on disk are then stale.
    """

    def check(coefficients):
        C = np.asarray(coefficients, dtype=np.float64)
        if C.shape != (1, 3) or not np.all((C >= 0) & (C <= 1)):
            raise ValueError("`coefficients` of a toy must be (1, 3) in [0, 1]")
        return C

    toy = ModelKind(
        name="toy-packaged",
        code=201,
        description="toy",
        parameters=("F0",),
        max_degree=0,
        check=check,
        evaluate=lambda *args: None,
        glsl_file="cf_fresnel_baselines.glsl",
        hlsl_file="none.hlsl",
        glsl_function="cf_schlick",
        preview_call="cf_schlick(NdotV, vec3(unpackHalf2x16(words[0]), unpackHalf2x16(words[1]).x))",
        material_template="none",
    )
    register_model_kind(toy)
    try:
        kinds = _module_kinds(three_package.kinds_module())
        types = three_package.kinds_types()
        stale = three_package.stale()
    finally:
        unregister_model_kind(toy.name)
    assert [k["name"] for k in kinds] == [*MODEL_KINDS, toy.name]
    entry = kinds[-1]
    assert (entry["parameters"], entry["maxDegree"], entry["splitSum"]) == (["F0"], 0, False)
    assert (entry["minimum"], entry["exclusiveMinimum"]) == ({"F0": 0}, {})
    assert "return cf_schlick(NdotV" in entry["glsl"] and "vec3 cf_schlick(" in entry["glsl"]
    assert "return cf_schlick(NdotV" in entry["modelTable"] and "#version" not in entry["modelTable"]
    assert '"toy-packaged"' in types.split("export type KindFields", 1)[0]
    assert "web/three/src/generated/kinds.js" in stale and "web/three/src/generated/kinds.d.ts" in stale
    assert three_package.stale() == []


def test_the_lut_layout_needs_a_and_b_equal_across_slices():
    data = np.array(default_lut().data, copy=True)
    data[3, 5, 7, 0] += 1e-3
    with pytest.raises(ValueError, match="A and B differ"):
        three_package.lut_planes(data)


@pytest.mark.slow  # starts a process (node)
def test_the_package_decodes_the_lut_bit_for_bit():
    node = shutil.which("node")
    assert node, "node is needed (docs/testing.md)"
    script = (
        "import('./web/three/src/lut.js').then(async (m) => { const l = await m.lutTexels();"
        " process.stdout.write(JSON.stringify([l.width, l.height, l.depth, l.alphaRange]) + '\\n');"
        " process.stdout.write(Buffer.from(l.data.buffer)); });"
    )
    done = subprocess.run(
        [node, "--input-type=module", "-e", script], cwd=three_package.ROOT, capture_output=True, timeout=120
    )
    assert done.returncode == 0, done.stderr.decode()
    head, _, body = done.stdout.partition(b"\n")
    lut = default_lut()
    depth, height, width = lut.shape
    assert json.loads(head) == [width, height, depth, list(lut.alpha_range)]
    # The texels of GET /api/v1/ibl-lut's file: after its 32-byte header, before its CRC.
    assert body == encode_lut(lut)[32:-4]
