"""
The three.js material and GLTFLoader plugin (static/three/coated_conductor.js)
in a real Chromium (SwiftShader WebGL2) against a real server: a stored fit's
glTF export loaded with the plugin renders what the editor's WebGL preview
renders at the same settings, and the physics; without the plugin the same
asset renders its fallback, a plausible metal, with no error
(tests/static/three_pages.py says what is compared and how).

Tolerances, Delta E 2000 over the ball's pixels with NdotV >= 0.1 (128 x 128,
about 10 800 pixels), each with headroom over what it measured here
(benchmarks/three_parity.py records the full table):

-   against the preview (coated-conductor) or numpy's twin (rgb-conductor):
    mean < ``PARITY_MEAN`` 0.05 (the issue's target 0.5; measured 0.006 for
    Au mirrors at eta_i 1.5, Cu rough at 1.8; 0.006-0.012 for the
    rgb-conductor), 99th percentile < 0.25 (measured 0.09-0.11: the
    outermost pixels, where three's mesh and the exact sphere differ), centre
    < 0.02 (measured 0.0004-0.004; 0.008 for the rgb-conductor's rough
    table, a 2048-point quadrature on SwiftShader's coarse sin and cos),
    ring near grazing < 0.15 (0.01-0.07);
-   against the physics (the spectral reference under the coat): mean <
    0.25, centre and ring < 0.3 (measured 0.11 / 0.19 / 0.09 for Au mirrors,
    the model's own float16 error, the paper's 0.14 for Au);
-   the fallback against the physics: centre < 4 (measured 2.5-3.1: Schlick
    base colour, three's coat at 1.5), its colour ordered as the metal's.
"""

from __future__ import annotations

import numpy as np
import pytest
from editor_pages import pages, chromium, live_server  # noqa: F401 (fixtures: one server and one Chromium a module)
from three_pages import create_fit, measure_three, open_example

from fitting.optics.library import library_material

pytestmark = [pytest.mark.server, pytest.mark.browser, pytest.mark.slow]

PARITY_MEAN, PARITY_P99, PARITY_CENTRE, PARITY_RING = 0.05, 0.25, 0.02, 0.15
PHYSICS_MEAN, PHYSICS_CENTRE, PHYSICS_RING = 0.25, 0.3, 0.3
FALLBACK_CENTRE = 4.0


@pytest.mark.parametrize("kind, material, eta_i, roughness, coat_roughness", [
    ("coated-conductor", "Au", 1.5, 0.0, 0.0),
    ("coated-conductor", "Cu", 1.8, 0.3, 0.1),
    ("rgb-conductor", "Au", 1.33, 0.3, 0.1),
], ids=["coated-Au-mirror", "coated-Cu-rough", "rgb-Au-rough"])
def test_plugin_matches_preview_and_physics(pages, live_server, kind, material, eta_i, roughness, coat_roughness):
    fit = create_fit(live_server, material, kind)
    page = pages.new(900, 700)
    open_example(page, live_server, fit["id"], eta_i)
    figures = measure_three(page, live_server, library_material(material), fit, eta_i, roughness, coat_roughness)
    assert figures["pixels"] > 10_000
    parity = figures["preview" if kind == "coated-conductor" else "twin"]
    assert parity["mean"] < PARITY_MEAN and parity["p99"] < PARITY_P99, parity
    assert parity["centre"] < PARITY_CENTRE and parity["ring"] < PARITY_RING, parity
    physics = figures["physics"]
    assert physics["mean"] < PHYSICS_MEAN, physics
    assert physics["centre"] < PHYSICS_CENTRE and physics["ring"] < PHYSICS_RING, physics
    # The fallback: a plausible metal of the same colour family, not the model.
    assert figures["fallback"]["centre"] < FALLBACK_CENTRE, figures["fallback"]
    r, g, b = figures["fallback_centre_rgb"]
    assert r > g > b > 0.1, figures["fallback_centre_rgb"]
    assert figures["fallback"]["mean"] > 5 * physics["mean"]


def test_roughness_and_coat_change_the_render(pages, live_server):
    """
    The material follows its roughness (the table is redrawn), the canvas
    shows both balls, and a direct light adds to the render.
    """
    fit = create_fit(live_server, "Cu", "coated-conductor")
    page = pages.new(900, 700)
    open_example(page, live_server, fit["id"], 1.5)
    smooth = measure_three(page, live_server, library_material("Cu"), fit, 1.5, 0.0, 0.0)
    rough = measure_three(page, live_server, library_material("Cu"), fit, 1.5, 0.6, 0.3)
    assert not np.allclose(smooth["centre_rgb"], rough["centre_rgb"], atol=1e-3)
    assert rough["preview"]["mean"] < PARITY_MEAN
    shown = page.evaluate("""() => ['model', 'fallback'].map((id) => {
        const c = document.getElementById(id), x = c.getContext('webgl2');
        const px = new Uint8Array(4);
        x.readPixels(c.width >> 1, c.height >> 1, 1, 1, x.RGBA, x.UNSIGNED_BYTE, px);
        return Array.from(px); })""")
    for rgba in shown:
        assert rgba[3] == 255 and rgba[0] > rgba[2] > 0, shown
    # A punctual light: the patched BRDF_GGX (the model at v.h) compiles and adds light.
    lit = page.evaluate("""async () => {
        const THREE = await import('three');
        const ball = window.cfThree.balls.model;
        const centre = () => { const px = ball.readFloat(32, 32, {}); return px[4 * (16 * 32 + 16)]; };
        const before = centre();
        const light = new THREE.DirectionalLight(0xffffff, 3);
        light.position.set(...ball.camera.position.toArray());
        ball.scene.add(light);
        return [before, centre()]; }""")
    assert lit[1] > lit[0] + 0.05, lit


def test_material_refuses_malformed_extensions(pages, live_server):
    """createCoatedConductorMaterial checks the extension object and names the field."""
    page = pages.new(400, 300)
    fit = create_fit(live_server, "Au", "coated-conductor")
    open_example(page, live_server, fit["id"], 1.5)
    messages = page.evaluate("""async () => {
        const { checkModel } = await import('/static/three/coated_conductor.js');
        const good = { kind: 'rgb-conductor', colorSpace: 'ACEScg', etaIRange: [1, 2.5], coatIor: 1.5,
                       coefficients: { n: [0.2, 0.5, 1.3], k: [3, 2.3, 1.9] } };
        const bad = [
            { ...good, kind: 'schlick' }, { ...good, colorSpace: 'sRGB' }, { ...good, coatIor: 0.5 },
            { ...good, coefficients: { n: [1, 1] , k: [0, 0, 0] } },
            { ...good, kind: 'coated-conductor', degree: 2, coefficients: { F0: [[1, 0, 0]], a: [], alpha: [] } },
            { ...good, kind: 'coated-conductor', degree: 5 },
        ];
        checkModel(good);
        return bad.map((m) => { try { checkModel(m); return null; } catch (e) { return e.message; } });
    }""")
    assert all(messages), messages
    for message, field in zip(messages, ["`kind`", "`colorSpace`", "`coatIor`", "n and k",
                                         "`coefficients.F0`", "`degree`"]):
        assert field in message, message
