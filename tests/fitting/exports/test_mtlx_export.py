"""
The MaterialX and OpenPBR exports in the real tool: the ``materialx``
package loads and validates them against its standard libraries, reads back
the intended values, and its GLSL generator makes a shader that
glslangValidator compiles.
"""

from __future__ import annotations

import shutil
import subprocess

import MaterialX as mx
import MaterialX.PyMaterialXGenGlsl as mx_gen_glsl
import MaterialX.PyMaterialXGenShader as mx_gen_shader
import numpy as np
import pytest

from fitting.exports import export_material, export_values
from fitting.optics.library import library_material

CASES = [("Cu", 1.5), ("Au", 2.0), ("Cr", 1.0)]


@pytest.fixture(scope="module")
def stdlib() -> mx.Document:
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    return lib


@pytest.fixture(scope="module", params=CASES, ids=[f"{m}-{e}" for m, e in CASES])
def values(request):
    name, eta_i = request.param
    return export_values(library_material(name), eta_i, tools=("mtlx", "openpbr"))


def load(text: str, stdlib: mx.Document) -> mx.Document:
    doc = mx.createDocument()
    mx.readFromXmlString(doc, text)
    doc.importLibrary(stdlib)
    return doc


def value_of(node: mx.Node, name: str):
    return node.getInputValue(name)


def conductor_input(graph: mx.NodeGraph, metal: mx.Node, key: str):
    """
    The conductor's ``key`` (ior, extinction) as written: (constant, slope
    per facing); a constant input has slope 0, a graph is
    max(slope * clamp(1 + N.V) + constant, lower bound) (docs/exports.md).
    """
    if metal.getConnectedNode(key) is None:
        return list(value_of(metal, key)), [0.0] * 3
    bounded = metal.getConnectedNode(key)
    assert bounded.getCategory() == "max"
    assert value_of(bounded, "in2") == pytest.approx({"ior": 1e-3, "extinction": 0.0}[key])
    affine = bounded.getConnectedNode("in1")
    assert affine.getCategory() == "add"
    scaled = affine.getConnectedNode("in1")
    assert scaled.getCategory() == "multiply"
    facing = scaled.getConnectedNode("in2")
    assert facing.getCategory() == "clamp"
    one_plus = facing.getConnectedNode("in")
    assert one_plus.getCategory() == "add" and value_of(one_plus, "in2") == pytest.approx(1.0)
    dot = one_plus.getConnectedNode("in1")
    assert dot.getCategory() == "dotproduct"
    assert {dot.getConnectedNode(i).getCategory() for i in ("in1", "in2")} == {"normal", "viewdirection"}
    return list(value_of(affine, "in2")), list(value_of(scaled, "in1"))


def glsl_compiles(doc: mx.Document, tmp_path) -> list[str]:
    """Generate GLSL for the document's material; compile both stages; return the sources."""
    generator = mx_gen_glsl.GlslShaderGenerator.create()
    context = mx_gen_shader.GenContext(generator)
    context.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    (material,) = doc.getMaterialNodes()
    shader = generator.generate(material.getName(), material, context)
    sources = []
    for stage, suffix in ((mx_gen_shader.PIXEL_STAGE, "frag"), (mx_gen_shader.VERTEX_STAGE, "vert")):
        source = shader.getSourceCode(stage)
        path = tmp_path / f"shader.{suffix}"
        path.write_text(source)
        result = subprocess.run(["glslangValidator", str(path)], capture_output=True, text=True, timeout=120)
        assert result.returncode == 0, result.stdout + result.stderr
        sources.append(source)
    return sources


def test_glslang_installed():
    assert shutil.which("glslangValidator"), "glslangValidator missing: run scripts/bootstrap"


class TestMtlx:
    def test_validates_and_reads_back(self, values, stdlib):
        doc = load(export_material(values, "mtlx", values.eta_i).decode(), stdlib)
        valid, message = doc.validate()
        assert valid, message
        (material,) = doc.getMaterialNodes()
        shader = material.getConnectedNode("surfaceshader")
        # MaterialX values are written with 6 significant digits
        # (fitting/exports/_xml.py): within 5e-6 relative; these inputs are
        # short decimals (1.5, 0.2, 0.03), exact in 6 digits, so approx's
        # default rel=1e-6 holds. Vectors: rtol 1e-5 = 2 x 5e-6; atol 1e-6 for
        # values in [0, 1] (at most 5e-7 off).
        coated = values.eta_i > 1.0
        assert value_of(shader, "base_roughness") == pytest.approx(values.roughness)
        (nodedef,) = [nd for nd in doc.getNodeDefs() if nd.getNodeString() == shader.getCategory()]
        graph = nodedef.getImplementation()
        metal = graph.getNode("metal")
        assert metal.getCategory() == "conductor_bsdf"
        # The values fitted to the coated metal seen from air.
        fitted = values.tools["mtlx"]
        for key in ("ior", "extinction"):
            const, slope = conductor_input(graph, metal, key)
            np.testing.assert_allclose(const, fitted[key], rtol=1e-5, atol=1e-9)
            np.testing.assert_allclose(slope, fitted[f"{key}_per_facing"], rtol=1e-5, atol=1e-9)
        surface = graph.getNode("shader")
        if not coated:
            # eta_i 1: no coat at all, the conductor straight into the surface.
            assert {i.getName() for i in nodedef.getActiveInputs()} == {"base_roughness"}
            assert graph.getNode("coat") is None and surface.getConnectedNode("bsdf") == metal
            return
        assert value_of(shader, "coat_ior") == pytest.approx(values.eta_i)
        assert value_of(shader, "coat_roughness") == pytest.approx(values.coat_roughness)
        assert {i.getName() for i in nodedef.getActiveInputs()} == {"base_roughness", "coat_roughness", "coat_ior"}
        coat = graph.getNode("coat")
        assert coat.getCategory() == "dielectric_bsdf"
        assert coat.getInput("ior").getInterfaceName() == "coat_ior"
        layer = graph.getNode("coated_metal")
        assert layer.getConnectedNode("top") == coat and layer.getConnectedNode("base") == metal
        assert surface.getConnectedNode("bsdf") == layer
        assert f"material: {values.name}" in material.getDocString()
        assert f"eta_i: {values.eta_i}" in material.getDocString()

    @pytest.mark.slow  # starts a process or GL context
    def test_glsl_compiles(self, values, stdlib, tmp_path):
        doc = load(export_material(values, "mtlx", values.eta_i).decode(), stdlib)
        pixel, _ = glsl_compiles(doc, tmp_path)
        # The conductor is called with the exported relative index as literals.
        n_literal = "vec3(" + ", ".join(f"{float(f'{v:.6g}'):.6f}" for v in values.tools["mtlx"]["ior"]) + ")"
        assert "mx_fresnel_conductor" in pixel and n_literal in pixel

    def test_validation_is_not_a_formality(self, values, stdlib):
        text = export_material(values, "mtlx", values.eta_i).decode()
        broken = load(text.replace('nodename="metal"', 'nodename="no_such_node"'), stdlib)
        assert not broken.validate()[0]


class TestOpenPBR:
    def test_validates_and_reads_back(self, values, stdlib):
        doc = load(export_material(values, "openpbr", values.eta_i).decode(), stdlib)
        valid, message = doc.validate()
        assert valid, message
        (material,) = doc.getMaterialNodes()
        shader = material.getConnectedNode("surfaceshader")
        assert shader.getCategory() == "open_pbr_surface"
        assert shader.getNodeDef().getName() == "ND_open_pbr_surface_surfaceshader"
        fitted = values.tools["openpbr"]
        np.testing.assert_allclose(list(value_of(shader, "base_color")), fitted["base_color"], atol=1e-6)
        np.testing.assert_allclose(list(value_of(shader, "specular_color")), fitted["specular_color"], atol=1e-6)
        # coat_darkening 1 (OpenPBR's default): the fit is made with it on;
        # no coat at all at eta_i 1.
        coat_weight = 1.0 if values.eta_i > 1.0 else 0.0
        for name, expected in (
            ("base_metalness", 1.0),
            ("coat_weight", coat_weight),
            ("coat_ior", values.eta_i),
            ("specular_roughness", values.roughness),
            ("coat_darkening", 1.0),
        ):
            assert value_of(shader, name) == pytest.approx(expected)
        assert "f82-tint" in material.getDocString()

    @pytest.mark.slow  # starts a process or GL context
    def test_glsl_compiles(self, values, stdlib, tmp_path):
        doc = load(export_material(values, "openpbr", values.eta_i).decode(), stdlib)
        pixel, _ = glsl_compiles(doc, tmp_path)
        assert "mx_fresnel_hoffman_schlick" in pixel

    @pytest.mark.slow  # starts a process or GL context
    def test_compile_check_is_not_a_formality(self, tmp_path):
        bad = tmp_path / "bad.frag"
        bad.write_text("#version 400\nvoid main() { vec3 x = undefined_thing; }\n")
        result = subprocess.run(["glslangValidator", str(bad)], capture_output=True, timeout=60)
        assert result.returncode != 0
