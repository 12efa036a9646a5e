"""
The Babylon.js package (web/babylon/, served at /static/babylon/, Babylon.js
itself at /vendor/babylon/) in a real Chromium (SwiftShader WebGL2) against
a real server: a stored fit's glTF export loaded by Babylon's glTF loader
with the package's extension draws what three.js draws with its own plugin
(tests/static/babylon_pages.py says what is compared and how), and
malformed extension objects draw the fallback with a warning.

Tolerance: mean Delta E 2000 over the ball's pixels with NdotV >= 0.1
(about 10 800 pixels) < ``PARITY_MEAN`` 0.05, 99th percentile < 0.3 (the
outermost pixels, where the two meshes differ), centre < 0.02; what
benchmarks/babylon_parity.py records is a few thousandths mean.

Cost: the shared server and Chromium, one fit, two pages.
"""

from __future__ import annotations

import pytest
from babylon_pages import measure_babylon, open_babylon, show_babylon
from editor_pages import Pages, chromium, live_server  # noqa: F401 (fixtures: one server and one Chromium a module)
from three_pages import create_fit, open_example, show_fit

pytestmark = [pytest.mark.server, pytest.mark.browser, pytest.mark.slow]

PARITY_MEAN, PARITY_P99, PARITY_CENTRE = 0.05, 0.3, 0.02

GOOD_RGB = {
    "kind": "rgb-conductor",
    "colorSpace": "ACEScg",
    "etaIRange": [1, 2.5],
    "coefficients": {"n": [0.2, 0.5, 1.3], "k": [3, 2.3, 1.9]},
}


def coat(ior: float) -> dict:
    """A whole clear coat of index ``ior`` (the draft KHR_materials_clearcoat_ior nested in it)."""
    return {"clearcoatFactor": 1, "extensions": {"KHR_materials_clearcoat_ior": {"clearcoatIor": ior}}}


# (what, extension object, the material's clear coat or None, what the warning names)
MALFORMED = [
    ("unknown kind", {**GOOD_RGB, "kind": "schlick"}, None, "`kind`"),
    ("coat index below 1", GOOD_RGB, coat(0.5), "`clearcoatIor`"),
    ("negative k", {**GOOD_RGB, "coefficients": {"n": [1, 1, 1], "k": [0, -1, 0]}}, None, "n > 0"),
    ("revision 1's coat", {**GOOD_RGB, "coatIor": 1.5}, None, "`coatIor`"),
]


@pytest.fixture(scope="module")
def pages(chromium, live_server):
    made = Pages(chromium)
    try:
        yield made.new(900, 700), made.new(900, 700), made.errors
    finally:
        for context in made.contexts:
            context.close()


def test_babylon_draws_what_three_draws(pages, live_server):
    """Cu (coated-conductor) at coat indices 1.0 and 2.0, smooth, white sky: Babylon.js against three.js."""
    three, babylon, errors = pages
    fit = create_fit(live_server, "Cu", "coated-conductor")
    for k, eta_i in enumerate((1.0, 2.0)):
        if k == 0:
            open_example(three, live_server, fit["id"], eta_i)
        else:
            show_fit(three, fit["id"], eta_i)
        show_babylon(babylon, live_server, fit["id"], eta_i)
        figures = measure_babylon(three, babylon)
        assert figures["pixels"] > 10_000, figures
        parity = figures["babylon_vs_three"]
        assert parity["mean"] < PARITY_MEAN and parity["p99"] < PARITY_P99, (eta_i, parity)
        assert parity["centre"] < PARITY_CENTRE, (eta_i, parity)
        plugin = babylon.evaluate("window.cfBabylon.material.pluginManager.getPlugin('CoatedConductor').coatIor")
        assert plugin == pytest.approx(eta_i)
    assert errors == []


def test_malformed_extensions_draw_the_fallback(pages, live_server):
    """
    A glTF document whose materials carry malformed extension objects loads
    through Babylon's loader without an exception: each such material has no
    plugin, with one console warning naming the field; the well-formed one
    beside them has the plugin.
    """
    _, babylon, _ = pages
    if babylon.evaluate("window.cfBabylon === undefined"):
        open_babylon(babylon, live_server, create_fit(live_server, "Cu", "coated-conductor")["id"], 1.5)
    objects = [(GOOD_RGB, coat(1.8))] + [(o, c) for _, o, c, _ in MALFORMED]
    result = babylon.evaluate(
        """async (objects) => {
        const { LoadAssetContainerAsync } = await import('@babylonjs/core/Loading/sceneLoader.js');
        const { EngineStore } = await import('@babylonjs/core/Engines/engineStore.js');
        const scene = EngineStore.LastCreatedScene;
        const json = { asset: { version: '2.0' }, extensionsUsed: ['EXT_materials_coated_conductor',
                           'KHR_materials_clearcoat', 'KHR_materials_clearcoat_ior'],
                       materials: objects.map(([o, c], i) => ({ name: `m${i}`, pbrMetallicRoughness: {
                           baseColorFactor: [0.9, 0.6, 0.3, 1], metallicFactor: 1 },
                           extensions: { EXT_materials_coated_conductor: o,
                                         ...(c ? { KHR_materials_clearcoat: c } : {}) } })),
                       meshes: [{ primitives: objects.map((_, i) => ({ attributes: { POSITION: 0 }, material: i })) }],
                       accessors: [{ bufferView: 0, componentType: 5126, count: 3, type: 'VEC3',
                                     min: [0, 0, 0], max: [1, 1, 0] }],
                       bufferViews: [{ buffer: 0, byteLength: 36 }],
                       buffers: [{ byteLength: 36, uri: 'data:application/octet-stream;base64,' +
                           btoa(String.fromCharCode(...new Uint8Array(new Float32Array([0,0,0, 1,0,0, 0,1,0]).buffer))) }],
                       nodes: [{ mesh: 0 }], scenes: [{ nodes: [0] }], scene: 0 };
        const warnings = [];
        const warn = console.warn;
        console.warn = (...args) => warnings.push(args.join(' '));
        try {
            const container = await LoadAssetContainerAsync(
                'data:' + JSON.stringify(json), scene, { pluginExtension: '.gltf' });
            const byName = Object.fromEntries(container.materials.map((m) => [m.name, m]));
            const drawn = objects.map((_, i) => Boolean(byName[`m${i}`]?.pluginManager?.getPlugin('CoatedConductor')));
            container.dispose();
            return { warnings, drawn };
        } finally {
            console.warn = warn;
        }
    }""",
        objects,
    )
    assert result["drawn"] == [True] + [False] * len(MALFORMED), result
    ours = [w for w in result["warnings"] if "EXT_materials_coated_conductor" in w]
    assert len(ours) == len(MALFORMED), result["warnings"]
    for (what, _, _, field), warning in zip(MALFORMED, ours):
        assert field in warning and "draws its fallback" in warning, (what, warning)
