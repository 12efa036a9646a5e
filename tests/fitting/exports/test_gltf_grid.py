"""
The sample asset of EXT_materials_coated_conductor
(docs/gltf/samples/CoatedConductorGrid/, written by
benchmarks/coated_conductor_grid.py) in the glTF-Sample-Assets layout: the
Khronos glTF validator reports no error and no warning on its .gltf (+ .bin)
and its .glb; every material's extension object validates against the
schema; the grid is a column per metal and a row per coat index, each
material's coat the row's; and fitting.exports.gltf_grid builds such grids
and refuses a ragged one.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

import jsonschema
import pytest

from fitting.exports import export_values
from fitting.exports.gltf_coated import EXTENSION_NAME, SCHEMA_PATH, coat_of
from fitting.exports.gltf_grid import SPACING, grid_asset, grid_glb, grid_gltf
from fitting.fits.kinds import fit_model
from fitting.optics.library import library_material

from test_gltf_export import khronos_report

ROOT = Path(__file__).resolve().parents[3]
SAMPLE = ROOT / "docs" / "gltf" / "samples" / "CoatedConductorGrid"
VALIDATOR = jsonschema.Draft202012Validator(json.loads(SCHEMA_PATH.read_text()))


def glb_json(data: bytes) -> dict:
    length, kind = struct.unpack_from("<II", data, 12)
    assert data[:4] == b"glTF" and kind == 0x4E4F534A
    return json.loads(data[20 : 20 + length])


def test_the_layout_of_a_sample():
    for name in (
        "README.md",
        "glTF/CoatedConductorGrid.gltf",
        "glTF/CoatedConductorGrid.bin",
        "glTF-Binary/CoatedConductorGrid.glb",
        "screenshot/screenshot.jpg",
    ):
        assert (SAMPLE / name).is_file(), name
    assert (SAMPLE / "screenshot" / "screenshot.jpg").read_bytes()[:3] == b"\xff\xd8\xff"  # a JPEG


@pytest.mark.slow  # starts the validator's node process twice
@pytest.mark.parametrize("path", ["glTF/CoatedConductorGrid.gltf", "glTF-Binary/CoatedConductorGrid.glb"])
def test_the_khronos_validator_accepts_the_sample(path):
    code, report = khronos_report(SAMPLE / path)
    assert code == 0, report["issues"]
    assert report["issues"]["numErrors"] == 0 and report["issues"]["numWarnings"] == 0, report
    # The extension and the coat index's draft are unknown to it: an information, never an error.
    assert {m["code"] for m in report["issues"]["messages"]} == {"UNSUPPORTED_EXTENSION"}
    assert report["info"]["materialCount"] == 24 and report["info"]["drawCallCount"] == 24


def test_the_grid_is_metals_by_coat_indices():
    text = json.loads((SAMPLE / "glTF" / "CoatedConductorGrid.gltf").read_text())
    binary = glb_json((SAMPLE / "glTF-Binary" / "CoatedConductorGrid.glb").read_bytes())
    assert text["buffers"][0]["uri"] == "CoatedConductorGrid.bin"
    assert {k: v for k, v in text.items() if k != "buffers"} == {k: v for k, v in binary.items() if k != "buffers"}
    metals, indices = set(), set()
    for node in text["nodes"]:
        metal, _, eta = node["name"].split()
        material = text["materials"][text["meshes"][node["mesh"]]["primitives"][0]["material"]]
        VALIDATOR.validate(material["extensions"][EXTENSION_NAME])
        factor, _, ior = coat_of(material)
        assert ior == pytest.approx(float(eta)) and factor == (1.0 if float(eta) > 1 else 0.0)
        metals.add(metal)
        indices.add(float(eta))
    assert len(metals) == 6 and indices == {1.0, 1.33, 1.5, 2.0}


def test_grid_asset_refuses_a_ragged_grid():
    with pytest.raises(ValueError, match="`rows`"):
        grid_asset([[None, None], [None]], "test")
    with pytest.raises(ValueError, match="`rows`"):
        grid_asset([], "test")
    with pytest.raises(ValueError, match="`bin_name`"):
        grid_gltf({}, b"", "../grid.bin")


@pytest.mark.slow  # a fit and two exports
def test_grid_asset_places_the_spheres():
    nk = library_material("Cu")
    packed = fit_model(nk, (1.0, 2.5), "coated-conductor").packed
    row = [export_values(nk, eta, model=packed, tools=("gltf",)) for eta in (1.0, 1.5)]
    asset, buffer = grid_asset([row], "test")
    assert [n["translation"][0] for n in asset["nodes"]] == [-SPACING / 2, SPACING / 2]
    text, binary = grid_gltf(asset, buffer, "grid.bin")
    assert binary == buffer and json.loads(text)["buffers"] == [{"byteLength": len(buffer), "uri": "grid.bin"}]
    assert glb_json(grid_glb(asset, buffer))["materials"] == asset["materials"]
