"""
EXT_materials_coated_conductor in the glTF export: every exported document
validates against the extension's JSON Schema (draft 2020-12, the
``jsonschema`` package) and passes the Khronos glTF validator with no error
and no warning; the schema refuses malformed extension objects; the
coefficients are the pack's float16 values, exactly.
"""

from __future__ import annotations

import copy
import json

import jsonschema
import numpy as np
import pytest

from fitting.exports import export_material
from fitting.exports.gltf_coated import CLEARCOAT_IOR, EXTENSION_NAME, SCHEMA_PATH, coat_of, coated_conductor_extension
from fitting.fits.kinds import fit_model
from fitting.models.pack import material_from_json, material_to_json
from fitting.optics.library import library_material

from test_gltf_export import khronos_report

SCHEMA = json.loads(SCHEMA_PATH.read_text())
VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)


@pytest.fixture(scope="module")
def packed():
    nk = library_material("Cu")
    return nk, {kind: fit_model(nk, (1.0, 2.5), kind).packed for kind in ("coated-conductor", "rgb-conductor")}


def extension_of(document: bytes) -> dict:
    return json.loads(document)["materials"][0]["extensions"][EXTENSION_NAME]


@pytest.fixture(scope="module")
def valid(packed):
    """Each kind's extension object as the export at eta_i 1.5 writes it: what the malformed cases break, a copy each."""
    nk, models = packed
    return {kind: extension_of(export_material(nk, "gltf", 1.5, model=model)) for kind, model in models.items()}


class TestSchema:
    def test_schema_is_draft_2020_12(self):
        assert SCHEMA["$schema"] == "https://json-schema.org/draft/2020-12/schema"
        jsonschema.Draft202012Validator.check_schema(SCHEMA)

    @pytest.mark.parametrize("kind", ["coated-conductor", "rgb-conductor"])
    @pytest.mark.parametrize("eta_i", [1.0, 1.33, 1.5, 2.5])
    def test_every_export_validates(self, packed, kind, eta_i):
        nk, models = packed
        material = json.loads(export_material(nk, "gltf", eta_i, model=models[kind]))["materials"][0]
        extension = material["extensions"][EXTENSION_NAME]
        VALIDATOR.validate(extension)
        # The coat is glTF's: a whole clear coat of index eta_i (none at 1).
        assert extension["kind"] == kind and coat_of(material)[::2] == ((1.0, eta_i) if eta_i > 1 else (0.0, 1.0))

    def test_single_index_fit_nine_coefficients(self):
        packed = fit_model(library_material("Au"), (1.5, 1.5), "coated-conductor", degree=0).packed
        extension, why = coated_conductor_extension(packed, 1.5)
        assert why is None and extension["degree"] == 0
        VALIDATOR.validate(extension)
        assert sum(len(row) for p in ("F0", "a", "alpha") for row in extension["coefficients"][p]) == 9

    def bad(self, extension, change):
        broken = copy.deepcopy(extension)
        change(broken)
        return list(VALIDATOR.iter_errors(broken))

    @pytest.mark.parametrize(
        "change",
        [
            lambda e: e.pop("kind"),
            lambda e: e.update(kind="schlick"),
            lambda e: e.update(colorSpace="sRGB"),
            lambda e: e.update(etaIRange=[0.9, 2.0]),
            lambda e: e.update(etaIRange=[1.0, 3.5]),
            lambda e: e.update(etaIRange=[1.0]),
            lambda e: e.update(coatIor=1.5),
            lambda e: e.update(degree=3),
            lambda e: e.pop("degree"),
            lambda e: e["coefficients"].pop("alpha"),
            lambda e: e["coefficients"]["F0"].pop(),
            lambda e: e["coefficients"]["a"][0].append(0.0),
            lambda e: e["coefficients"]["F0"][1].__setitem__(0, "0.5"),
            lambda e: e["coefficients"]["F0"][1].__setitem__(0, 1.0e6),
            lambda e: e["coefficients"].update(n=[1, 1, 1]),
            lambda e: e.update(extra_field=1),
        ],
        ids=[
            "no-kind",
            "unknown-kind",
            "colour-space",
            "range-low",
            "range-high",
            "range-short",
            "revision-1-coat",
            "degree-3",
            "no-degree",
            "no-alpha",
            "two-rows",
            "long-row",
            "string",
            "past-float16",
            "stray-n",
            "unknown-property",
        ],
    )
    def test_refuses_malformed_coated_conductor(self, valid, change):
        VALIDATOR.validate(valid["coated-conductor"])
        assert self.bad(valid["coated-conductor"], change)

    @pytest.mark.parametrize(
        "change",
        [
            lambda e: e["coefficients"].update(n=[0.0, 1.0, 1.0]),
            lambda e: e["coefficients"].update(k=[-0.1, 1.0, 1.0]),
            lambda e: e["coefficients"].update(k=[1.0, 1.0]),
            lambda e: e.update(degree=0),
            lambda e: e["coefficients"].update(F0=[[0.5]] * 3),
        ],
        ids=["n-zero", "k-negative", "k-two", "degree", "stray-F0"],
    )
    def test_refuses_malformed_rgb_conductor(self, valid, change):
        VALIDATOR.validate(valid["rgb-conductor"])
        assert self.bad(valid["rgb-conductor"], change)


class TestExport:
    @pytest.mark.parametrize("kind", ["coated-conductor", "rgb-conductor"])
    def test_coefficients_are_the_packs(self, packed, kind):
        nk, models = packed
        extension = extension_of(export_material(nk, "gltf", 1.8, model=models[kind]))
        view = material_to_json(models[kind])
        assert extension["coefficients"] == view["coefficients"]
        round_trip = material_from_json({**view, "coefficients": extension["coefficients"]})
        np.testing.assert_array_equal(round_trip.coefficients, models[kind].coefficients)

    def test_used_not_required_fallback_kept(self, packed):
        nk, models = packed
        asset = json.loads(export_material(nk, "gltf", 1.5, model=models["coated-conductor"]))
        assert asset["extensionsUsed"] == ["KHR_materials_clearcoat", CLEARCOAT_IOR, EXTENSION_NAME]
        assert "extensionsRequired" not in asset
        material = asset["materials"][0]
        assert material["pbrMetallicRoughness"]["metallicFactor"] == 1.0
        # The coat is the clear coat's, whole, its index in the nested draft; the extension carries the metal.
        clearcoat = material["extensions"]["KHR_materials_clearcoat"]
        assert clearcoat["clearcoatFactor"] == 1.0
        assert clearcoat["extensions"][CLEARCOAT_IOR] == {"clearcoatIor": 1.5}
        assert not {"coatIor", "coatFactor", "coatRoughnessFactor"} & set(material["extensions"][EXTENSION_NAME])

    def test_outside_the_fits_range_omitted_with_reason(self):
        nk = library_material("Cu")
        model = fit_model(nk, (1.2, 2.0), "coated-conductor").packed
        asset = json.loads(export_material(nk, "gltf", 2.5, model=model))
        assert asset["extensionsUsed"] == ["KHR_materials_clearcoat", CLEARCOAT_IOR]
        assert EXTENSION_NAME not in asset["materials"][0]["extensions"]
        assert "[1.2, 2]" in asset["materials"][0]["extras"]["coated_fresnel"]["coated_conductor_extension"]

    def test_rgb_conductor_any_index(self):
        nk = library_material("Cu")
        model = fit_model(nk, (1.2, 2.0), "rgb-conductor").packed
        material = json.loads(export_material(nk, "gltf", 2.9, model=model))["materials"][0]
        assert EXTENSION_NAME in material["extensions"] and coat_of(material)[2] == 2.9

    def test_model_must_be_packed(self):
        with pytest.raises(ValueError, match="`model` must be a PackedMaterial"):
            export_material(library_material("Cu"), "gltf", 1.5, model={"kind": "x"})


@pytest.mark.slow
class TestKhronosValidator:
    @pytest.mark.parametrize("kind", ["coated-conductor", "rgb-conductor"])
    def test_no_error_no_warning(self, packed, kind, tmp_path):
        nk, models = packed
        path = tmp_path / "cu.gltf"
        path.write_bytes(export_material(nk, "gltf", 1.33, model=models[kind]))
        code, report = khronos_report(path)
        assert code == 0, report["issues"]
        assert report["issues"]["numErrors"] == 0 and report["issues"]["numWarnings"] == 0, report
        # The validator knows neither extension (nor the coat index's draft): an information, never an error.
        assert {m["code"] for m in report["issues"]["messages"]} == {"UNSUPPORTED_EXTENSION"}
        assert report["info"]["extensionsUsed"] == ["KHR_materials_clearcoat", CLEARCOAT_IOR, EXTENSION_NAME]
