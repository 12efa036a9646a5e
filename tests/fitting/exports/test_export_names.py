"""
Export names and identity: every fit and coat index names its own node
definition, node graph and material, so exports merge in MaterialX itself
(``importLibrary``) with nothing lost; every export carries the full fit id,
the service version and the coat index.
"""

from __future__ import annotations

import dataclasses
import json
from types import SimpleNamespace

import MaterialX as mx
import numpy as np
import pytest

from fitting.exports import export_material, export_values
from fitting.exports._xml import IDENTITY_ATTRIBUTES
from fitting.exports.naming import check_fit_id, element_stem, eta_tag, export_id
from fitting.exports.values import project_version
from fitting.optics.library import library_material

METALS = ("Au", "Cu", "Ag")
ETAS = (1.0, 1.33, 1.5)
FIT_A = "1a2b3c4d" + "0" * 24
FIT_B = "9f8e7d6c" + "1" * 24


@pytest.fixture(scope="module")
def stdlib() -> mx.Document:
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    return lib


@pytest.fixture(scope="module")
def twenty_exports() -> list[str]:
    """3 metals x 3 coat indices x (MaterialX, OpenPBR), and gold at 1.33 of a second fit: 20."""
    texts = []
    for metal in METALS:
        for eta in ETAS:
            values = export_values(library_material(metal), eta, tools=("mtlx", "openpbr"), fit_id=FIT_A)
            texts += [export_material(values, f, eta).decode() for f in ("mtlx", "openpbr")]
            if (metal, eta) == ("Au", 1.33):
                other = dataclasses.replace(values, fit_id=FIT_B)
                texts += [export_material(other, f, eta).decode() for f in ("mtlx", "openpbr")]
    assert len(texts) == 20
    return texts


def merged(texts: list[str]) -> mx.Document:
    """The exports merged as a pipeline does: each read, then imported into one document."""
    doc = mx.createDocument()
    for text in texts:
        part = mx.createDocument()
        mx.readFromXmlString(part, text)
        doc.importLibrary(part)
    return doc


class TestNames:
    def test_eta_tag(self):
        assert [eta_tag(e) for e in (1.0, 1.33, 1.5, 2.0, 1.23456)] == [
            "eta1",
            "eta1p33",
            "eta1p5",
            "eta2",
            "eta1p2346",
        ]

    def test_stem(self):
        # What the names are made of, without a fit (the fields ExportValues has).
        values = SimpleNamespace(
            name="Au", source="s", origin="o", eta_i=1.0, model=None, target_ACEScg=np.full((4, 3), 0.5), fit_id=FIT_A
        )
        assert element_stem(values) == "Au_1a2b3c4d_eta1"
        # No stored fit: a content address, the same for the same data, another for other data.
        content = SimpleNamespace(**{**vars(values), "fit_id": None})
        assert export_id(content) == export_id(SimpleNamespace(**vars(content))) != FIT_A
        other = SimpleNamespace(**{**vars(content), "target_ACEScg": np.full((4, 3), 0.25)})
        assert len(export_id(content)) == 32 and export_id(other) != export_id(content)

    @pytest.mark.parametrize("bad", ["1a2b", "G" * 32, "1A2B3C4D" * 4, 7])
    def test_bad_fit_id(self, bad):
        with pytest.raises(ValueError, match="`fit_id` must be 32 lower-case hex digits"):
            check_fit_id(bad)


@pytest.mark.slow  # nine export fits, about 10 s
class TestMerge:
    def test_twenty_exports_merge_into_twenty_materials(self, twenty_exports, stdlib):
        doc = merged(twenty_exports)
        materials = doc.getMaterialNodes()
        assert len(materials) == 20
        assert len({m.getName() for m in materials}) == 20
        assert len(doc.getNodeDefs()) == 10 and len(doc.getNodeGraphs()) == 10
        doc.importLibrary(stdlib)
        valid, message = doc.validate()
        assert valid, message
        # Each material keeps its fit's full id, the version and the coat index.
        ids = {m.getAttribute(IDENTITY_ATTRIBUTES["fit_id"]) for m in materials}
        assert ids == {FIT_A, FIT_B}
        assert {m.getAttribute(IDENTITY_ATTRIBUTES["service_version"]) for m in materials} == {project_version()}
        assert {float(m.getAttribute(IDENTITY_ATTRIBUTES["eta_i"])) for m in materials} == set(ETAS)
        named = doc.getNodeDef("ND_coated_metal_Au_1a2b3c4d_eta1p33")
        assert named is not None and named.getImplementation().getName() == "NG_coated_metal_Au_1a2b3c4d_eta1p33"

    def test_the_count_can_fail(self, twenty_exports):
        # The same export twice is one material: importLibrary keeps the first of a name.
        assert len(merged(twenty_exports[:1] * 2).getMaterialNodes()) == 1


@pytest.fixture(scope="module")
def cu_values():
    return export_values(library_material("Cu"), 1.5, tools=("gltf", "blender", "blender-conductor"), fit_id=FIT_A)


@pytest.mark.slow  # one export fit of three tools, about 3 s
class TestIdentity:
    def test_gltf(self, cu_values):
        asset = json.loads(export_material(cu_values, "gltf", 1.5))
        for extras in (asset["asset"]["extras"], asset["materials"][0]["extras"]):
            info = extras["coated_fresnel"]
            assert info["fit_id"] == FIT_A and info["eta_i"] == 1.5
            assert info["service_version"] == project_version() and info["working_space"] == "lin_rec709"
        assert asset["materials"][0]["name"] == "Cu_1a2b3c4d_eta1p5"

    def test_blender(self, cu_values):
        script = export_material(cu_values, "blender", 1.5).decode()
        assert "MATERIAL_NAME = 'Cu_1a2b3c4d_eta1p5'" in script
        assert f"'fit_id': '{FIT_A}'" in script and "WORKING_SPACE = 'lin_rec709'" in script
