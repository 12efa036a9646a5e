"""
The three.js package's node material (``coated-conductor-three/webgpu``,
web/three/src/node_material.js) against its WebGL material:

-   each kind's TSL twin (web/three/src/node_models.js), evaluated on
    numbers by Node at sample cosines, is the registry's own formula
    (``ModelKind.evaluate`` on the float16 coefficients) for every
    registered kind, at coat indices across the fit's range;
-   in Chromium, the same extension object drawn by ``WebGLRenderer`` with
    the package's material and by ``WebGPURenderer`` (its WebGL2 backend:
    headless Chromium has no WebGPU adapter) with the node material, on the
    package test's shader ball under the white sky, agrees within 0.05 mean
    Delta E 2000 (tests/static/three_node_pages.py): both kinds, coat
    indices 1.0 to 2.0, smooth; and one rough setting with a directional
    light, which the white sky alone leaves out; and a glTF loaded through
    the package's GLTFLoader plugin, its material turned into the node
    material by ``useCoatedConductorNodeMaterials``; two node materials of
    one kind alive together each draw their own model.

Cost: one Node run; one folder and one page (SwiftShader WebGL2, 128 x
128, two renderers), ten scenes.
"""

from __future__ import annotations

import json
import shutil
import subprocess

import numpy as np
import pytest
from editor_pages import _CHROMIUM
from three_node_pages import PACKAGE, draw_both, draw_gltf, draw_pair, parity, parity_page, write_folder
from three_pages import serve

from fitting.exports import export_material
from fitting.fits.kinds import fit_model
from fitting.models.kinds import MODEL_KINDS
from fitting.optics.library import library_material

ETAS = (1.0, 1.33, 1.5, 2.0)
PARITY_MEAN = 0.05
MUS = [0.0, 0.02, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 1.0]

EVALUATE = """
import { MODEL_KINDS } from "./src/generated/kinds.js";
import { evaluateModel } from "./src/node_models.js";
const [models, mus] = JSON.parse(process.argv[1]);
const byName = new Map(MODEL_KINDS.map((kind) => [kind.name, kind]));
console.log(JSON.stringify(models.map((model) => evaluateModel(byName.get(model.kind), model, mus))));
"""


@pytest.fixture(scope="module")
def models():
    """Cu's extension object of each kind at each coat index of ETAS: [(kind, eta_i, object)]."""
    nk = library_material("Cu")
    out = []
    for kind in MODEL_KINDS:
        packed = fit_model(nk, (1.0, 2.5), kind).packed
        for eta_i in ETAS:
            document = json.loads(export_material(nk, "gltf", eta_i, model=packed))
            out.append((kind, eta_i, document["materials"][0]["extensions"]["EXT_materials_coated_conductor"]))
    return out


@pytest.mark.slow
@pytest.mark.numeric
def test_each_kind_s_tsl_twin_is_the_registry_s_formula(models):
    """node_models.js on numbers (Node) against ModelKind.evaluate on the float16 coefficients."""
    node = shutil.which("node")
    assert node, "node is part of the project's toolchain (scripts/bootstrap)"
    objects = [{**model, "coatIor": eta_i} for _, eta_i, model in models]  # under the clear coat's index
    done = subprocess.run(
        [node, "--input-type=module", "-e", EVALUATE, json.dumps([objects, MUS])],
        cwd=PACKAGE,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    values = json.loads(done.stdout)
    assert {kind for kind, _, _ in models} == set(MODEL_KINDS)
    for (kind, eta_i, model), got in zip(models, values, strict=True):
        registry = MODEL_KINDS[kind]
        coefficients = np.array([model["coefficients"][p] for p in registry.parameters], dtype=np.float16)
        if registry.polynomial:  # the rows padded with zero powers, as the shaders unpack them
            padded = np.zeros(registry.shape(registry.max_degree), dtype=np.float16)
            padded[..., : coefficients.shape[-1]] = coefficients
            coefficients = padded
        want = registry.evaluate(np.array(MUS), eta_i, coefficients.astype(np.float64), tuple(model["etaIRange"]))
        np.testing.assert_allclose(np.array(got), want, rtol=0, atol=2e-6, err_msg=f"{kind} at eta_i {eta_i}")


@pytest.fixture(scope="module")
def chromium():
    """The test process's one Chromium (editor_pages), without the service."""
    return _CHROMIUM.get()


@pytest.mark.browser
@pytest.mark.slow
def test_webgl_and_the_node_material_draw_the_same_image(models, chromium, tmp_path):
    write_folder(tmp_path)
    nk = library_material("Cu")
    packed = fit_model(nk, (1.0, 2.5), next(iter(MODEL_KINDS))).packed
    document = export_material(nk, "gltf", 1.5, model=packed)
    (tmp_path / "coated.gltf").write_bytes(document if isinstance(document, bytes) else document.encode())
    scenes = [(kind, eta_i, model, 0.0, 0.0, False) for kind, eta_i, model in models]
    scenes += [(kind, 1.5, model, 0.3, 0.1, True) for kind, eta_i, model in models if eta_i == 1.5]
    with serve(tmp_path) as site, parity_page(chromium, site) as (page, errors, backend):
        assert backend == "WebGL2"  # forceWebGL: the node material on WebGPURenderer's WebGL2 backend
        for kind, eta_i, model, roughness, coat_roughness, lit in scenes:
            webgl, node = draw_both(page, model, roughness, coat_roughness, lit, coat_ior=eta_i)
            found = parity(webgl, node)
            assert found["pixels"] > 10_000, found
            assert found["mean"] <= PARITY_MEAN, (kind, eta_i, roughness, lit, found)
        # Two materials of one kind alive together: each draws its own model (no program shared between them).
        first, last = (
            (model, eta_i) for kind, eta_i, model in models if kind == models[0][0] and eta_i in (ETAS[0], ETAS[-1])
        )
        gl_a, node_a, gl_b, node_b = draw_pair(page, first, last, 0.3, 0.1)
        assert parity(gl_a, node_a)["mean"] <= PARITY_MEAN and parity(gl_b, node_b)["mean"] <= PARITY_MEAN
        assert parity(gl_a, gl_b)["mean"] > 1  # the two models differ: the check above can see a swap
        # A glTF through the loader plugin, its material made a node material by useCoatedConductorNodeMaterials.
        webgl, node, twin = draw_gltf(page, "coated.gltf", 0.3, 0.1, True)
        assert twin
        assert parity(webgl, node)["mean"] <= PARITY_MEAN
        assert errors == []
