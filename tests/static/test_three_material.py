"""
The three.js material and GLTFLoader plugin (web/three/, served at /static/three/)
in a real Chromium (SwiftShader WebGL2) against a real server: a stored fit's
glTF export loaded with the plugin renders the same fit composed with the
full air-coat-metal stack in numpy (both kinds, mirror and rough lobes under
the white sky), the editor's preview's own parts composed with that stack
(white sky, studio and outdoor), and the physics; without the plugin the
same asset renders its fallback, a plausible metal further from the physics,
with no error; malformed extension objects draw the fallback with a
warning; the coat is the material's clear coat (its textures and the index
in KHR_materials_clearcoat_ior); the exporter plugin writes the extension
back (tests/static/three_pages.py says what is compared and how).

Cost: the shared server and Chromium, and one page for the module, loaded
with the first fit and coat index; each other is put on it with
cfThree.setFit, so that each environment is prefiltered (three's PMREM, the
page's slowest step in SwiftShader) once a module; each renders several
settings (the page relights with cfThree.setEnvironment and the material
takes each roughness in turn).

Tolerances, Delta E 2000 over the ball's pixels with NdotV >= 0.1 (128 x 128,
about 10 800 pixels), each with headroom over what
benchmarks/three_parity.py records (benchmarks/records/three_parity.md):

-   white sky, against the fit through the full stack (``composed``) and
    the preview's parts through it (``preview``): mean < ``PARITY_MEAN``
    0.05 (measured a few thousandths smooth, about 0.03 rough), 99th
    percentile < 0.25 (the outermost pixels, where three's mesh and the
    exact sphere differ), centre < 0.02, ring near grazing < 0.15;
-   studio and outdoor, against the preview as it draws (no bounces, and
    its own environment filter and colour space of the lighting product):
    mean < ``ENVIRONMENT_BOUNDS`` (studio 3, outdoor 6); against the
    preview's parts lit as three lights them with the stack
    (``preview_rec709``), mean < ``LIT_MEAN`` 1.5 (the rest is the filters
    and the highlights' edges);
-   against the physics (the spectral reference through the same stack):
    mean < 0.25, centre and ring < 0.3 (the model's own float16 error);
-   the fallback against the physics: centre < 4, its colour ordered as the
    metal's, and further from the physics than the plugin.
"""

from __future__ import annotations

import numpy as np
import pytest
from editor_pages import chromium, live_server  # noqa: F401 (fixtures: one server and one Chromium a module)
from three_pages import ExamplePage, create_fit, example_page, measure_three

from fitting.optics.library import library_material

pytestmark = [pytest.mark.server, pytest.mark.browser, pytest.mark.slow]

PARITY_MEAN, PARITY_P99, PARITY_CENTRE, PARITY_RING = 0.05, 0.25, 0.02, 0.15
PHYSICS_MEAN, PHYSICS_CENTRE, PHYSICS_RING = 0.25, 0.3, 0.3
FALLBACK_CENTRE = 4.0
# environment -> bound on the mean Delta E against the preview (see the docstring).
ENVIRONMENT_BOUNDS = {"studio": 3.0, "outdoor": 6.0}
LIT_MEAN = 1.5


class Session(ExamplePage):
    """The module's one example page and the fits it made."""

    def __init__(self, page, server, errors):
        super().__init__(page, server, errors)
        self.fits: dict = {}

    def fit(self, material: str, kind: str) -> dict:
        if (material, kind) not in self.fits:
            self.fits[material, kind] = create_fit(self.server, material, kind)
        return self.fits[material, kind]

    def example(self, fit: dict, eta_i: float):
        """The page showing ``fit`` at ``eta_i`` (loaded with the module's first, then ``cfThree.setFit``)."""
        return self.show(fit["id"], eta_i)


@pytest.fixture(scope="module")
def session(chromium, live_server):
    with example_page(chromium, live_server, Session) as made:
        yield made


@pytest.fixture(autouse=True)
def no_page_errors(session):
    """No test may make the page log an error."""
    with session.no_new_errors():
        yield


def check_white_sky(figures, kind):
    assert figures["pixels"] > 10_000
    for name in ("preview", "composed"):
        parity = figures[name]
        assert parity["mean"] < PARITY_MEAN and parity["p99"] < PARITY_P99, (name, parity)
        assert parity["centre"] < PARITY_CENTRE and parity["ring"] < PARITY_RING, (name, parity)
    physics = figures["physics"]
    assert physics["mean"] < PHYSICS_MEAN, physics
    assert physics["centre"] < PHYSICS_CENTRE and physics["ring"] < PHYSICS_RING, physics
    # The fallback: a plausible metal of the same colour family, never closer to the physics.
    assert figures["fallback"]["centre"] < FALLBACK_CENTRE, figures["fallback"]
    r, g, b = figures["fallback_centre_rgb"]
    assert r > g > b > 0.1, figures["fallback_centre_rgb"]
    assert figures["fallback"]["mean"] > physics["mean"], (figures["fallback"], physics)


@pytest.mark.parametrize(
    "kind, material, eta_i, env, lobe",
    [
        ("coated-conductor", "Au", 1.5, "outdoor", (0.3, 0.1)),
        ("rgb-conductor", "Au", 1.33, "studio", (0.0, 0.0)),
    ],
    ids=["coated-Au", "rgb-Au"],
)
def test_plugin_matches_preview_and_physics(session, kind, material, eta_i, env, lobe):
    """
    White sky, mirror and rough: the preview, the twin and the physics; a
    lobe under another of the preview's environments: the preview (the
    benchmark covers every kind, environment and lobe).
    """
    fit = session.fit(material, kind)
    page = session.example(fit, eta_i)
    nk = library_material(material)
    for roughness, coat_roughness in [(0.0, 0.0), (0.3, 0.1)]:
        check_white_sky(measure_three(page, session.server, nk, fit, eta_i, roughness, coat_roughness), kind)
    figures = measure_three(page, session.server, nk, fit, eta_i, *lobe, env)
    assert figures["pixels"] > 10_000
    assert figures["preview"]["mean"] < ENVIRONMENT_BOUNDS[env], (env, figures["preview"])
    assert figures["preview_rec709"]["mean"] < LIT_MEAN, (env, figures["preview_rec709"])


def test_roughness_and_coat_change_the_render(session):
    """
    Cu at eta_i 1.8, smooth (every white-sky bound) and rough; the
    material follows its roughness (the table is redrawn), the canvas shows
    both balls, and a direct light adds to the render.
    """
    fit = session.fit("Cu", "coated-conductor")
    page = session.example(fit, 1.8)
    smooth = measure_three(page, session.server, library_material("Cu"), fit, 1.8, 0.0, 0.0)
    rough = measure_three(page, session.server, library_material("Cu"), fit, 1.8, 0.6, 0.3)
    check_white_sky(smooth, "coated-conductor")
    assert rough["preview"]["mean"] < PARITY_MEAN, rough["preview"]
    assert rough["composed"]["mean"] < PARITY_MEAN, rough["composed"]
    assert not np.allclose(smooth["centre_rgb"], rough["centre_rgb"], atol=1e-3)
    # Each canvas shows its ball (a copy of the shared renderer's image).
    shown = page.evaluate("""() => ['model', 'fallback'].map((id) => {
        const c = document.getElementById(id);
        return Array.from(c.getContext('2d').getImageData(c.width >> 1, c.height >> 1, 1, 1).data); })""")
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
        const after = centre();
        ball.scene.remove(light);
        return [before, after]; }""")
    assert lit[1] > lit[0] + 0.05, lit


# Malformed or out-of-range extension objects, each with what its warning names.
GOOD_RGB = {
    "kind": "rgb-conductor",
    "colorSpace": "ACEScg",
    "etaIRange": [1, 2.5],
    "coefficients": {"n": [0.2, 0.5, 1.3], "k": [3, 2.3, 1.9]},
}
GOOD_COATED = {
    "kind": "coated-conductor",
    "colorSpace": "ACEScg",
    "etaIRange": [1, 2],
    "degree": 0,
    "coefficients": {"F0": [[0.9], [0.7], [0.4]], "a": [[0.1], [0.2], [0.1]], "alpha": [[5.0], [4.0], [3.0]]},
}


def coat(ior) -> dict:
    """A whole clear coat of index ``ior`` (the draft KHR_materials_clearcoat_ior nested in it)."""
    return {"clearcoatFactor": 1, "extensions": {"KHR_materials_clearcoat_ior": {"clearcoatIor": ior}}}


# (what, extension object, what the warning names, and the material's clear coat if the case is in it)
MALFORMED = [
    ("not an object", [1, 2, 3], "must be an object"),
    ("null", None, "must be an object"),
    ("unknown kind", {**GOOD_RGB, "kind": "schlick"}, "`kind`"),
    ("colour space", {**GOOD_RGB, "colorSpace": "sRGB"}, "`colorSpace`"),
    ("coat index below 1", GOOD_RGB, "`clearcoatIor`", coat(0.5)),
    ("coat index a string", GOOD_RGB, "`clearcoatIor`", coat("1.5")),
    ("coat index outside the fit", GOOD_COATED, "outside", coat(2.4)),
    ("glTF's 1.5 outside the fit", {**GOOD_COATED, "etaIRange": [1.8, 2]}, "outside", {"clearcoatFactor": 0.5}),
    ("revision 1's coat index", {**GOOD_RGB, "coatIor": 1.5}, "`coatIor`"),
    ("range reversed", {**GOOD_COATED, "etaIRange": [2, 1]}, "`etaIRange`"),
    ("range missing", {k: v for k, v in GOOD_RGB.items() if k != "etaIRange"}, "`etaIRange`"),
    ("n of two", {**GOOD_RGB, "coefficients": {"n": [1, 1], "k": [0, 0, 0]}}, "n > 0"),
    ("negative k", {**GOOD_RGB, "coefficients": {"n": [1, 1, 1], "k": [0, -1, 0]}}, "n > 0"),
    ("no coefficients", {k: v for k, v in GOOD_RGB.items() if k != "coefficients"}, "`coefficients`"),
    ("rows too short", {**GOOD_COATED, "degree": 2}, "`coefficients.F0`"),
    ("degree 5", {**GOOD_COATED, "degree": 5}, "`degree`"),
    (
        "beyond float16",
        {**GOOD_COATED, "coefficients": {**GOOD_COATED["coefficients"], "alpha": [[1e6], [4.0], [3.0]]}},
        "`coefficients.alpha`",
    ),
    ("revision 1's coat factor", {**GOOD_RGB, "coatFactor": 1}, "`coatFactor`"),
    ("unknown property", {**GOOD_RGB, "tint": [1, 0, 0]}, "`tint`"),
]


def test_malformed_extensions_draw_the_fallback(session):
    """
    A glTF document whose materials carry each malformed or out-of-range
    extension object loads through GLTFLoader with the plugin without an
    exception: each such material is the fallback (the loader's own
    material, no model), with one console warning naming the field; the
    well-formed ones beside them draw the model.
    """
    page = session.example(session.fit("Cu", "coated-conductor"), 1.8)
    objects = [(GOOD_RGB, None), (GOOD_COATED, coat(1.2))] + [(o, (c or [None])[0]) for _, o, _, *c in MALFORMED]
    result = page.evaluate(
        """async (objects) => {
        const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
        const { CoatedConductorExtension } = await import('/static/three/index.js');
        const json = { asset: { version: '2.0' }, extensionsUsed: ['EXT_materials_coated_conductor',
                           'KHR_materials_clearcoat', 'KHR_materials_clearcoat_ior'],
                       materials: objects.map(([o, c], i) => ({ name: `m${i}`, pbrMetallicRoughness: {
                           baseColorFactor: [0.9, 0.6, 0.3, 1], metallicFactor: 1 },
                           extensions: { EXT_materials_coated_conductor: o,
                                         ...(c ? { KHR_materials_clearcoat: c } : {}) } })) };
        const warnings = [];
        const warn = console.warn;
        console.warn = (...args) => warnings.push(args.join(' '));
        try {
            const loader = new GLTFLoader();
            loader.register((parser) => new CoatedConductorExtension(parser));
            const gltf = await loader.parseAsync(JSON.stringify(json), '');
            const materials = await Promise.all(objects.map((_, i) => gltf.parser.getDependency('material', i)));
            return { warnings, drawn: materials.map((m) => Boolean(m.userData.coatedConductor)),
                     types: materials.map((m) => m.type) };
        } finally {
            console.warn = warn;
        }
    }""",
        objects,
    )
    assert result["drawn"] == [True, True] + [False] * len(MALFORMED), result
    assert len(result["warnings"]) == len(MALFORMED), result["warnings"]
    for (what, _, field, *_), warning in zip(MALFORMED, result["warnings"]):
        assert field in warning and "draws its fallback" in warning, (what, warning)


def test_export_round_trip_keeps_the_extension(session):
    """
    A fit's export loaded with the plugin, written by GLTFExporter with the
    exporter plugin and loaded again: the extension objects and the
    fallback's clear coat are the file's, and the model is drawn again.
    """
    fit = session.fit("Cu", "coated-conductor")
    page = session.example(fit, 1.8)
    result = page.evaluate(
        """async (url) => {
        const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
        const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
        const { CoatedConductorExtension, CoatedConductorExporterExtension } =
            await import('/static/three/index.js');
        const original = await (await fetch(url)).json();
        const load = async (source) => {
            const loader = new GLTFLoader();
            loader.register((parser) => new CoatedConductorExtension(parser));
            return loader.parseAsync(JSON.stringify(source), '');
        };
        const first = await load(original);
        const exporter = new GLTFExporter();
        exporter.register((writer) => new CoatedConductorExporterExtension(writer));
        const written = await exporter.parseAsync(first.scene, { binary: false });
        const second = await load(written);
        let drawn = null;
        second.scene.traverse((o) => { if (o.isMesh) drawn = Boolean(o.material.userData.coatedConductor?.readTable); });
        const ext = (doc) => doc.materials[0].extensions;
        return { original: ext(original), written: ext(written), used: written.extensionsUsed,
                 required: written.extensionsRequired ?? [], extras: written.materials[0].extras ?? {}, drawn };
    }""",
        f"{session.server}/api/v1/fits/{fit['id']}/pack?format=gltf&eta_i=1.8",
    )
    for name in ("EXT_materials_coated_conductor", "KHR_materials_clearcoat"):
        assert result["written"][name] == result["original"][name], name
    assert "EXT_materials_coated_conductor" in result["used"] and result["required"] == []
    assert "coatedConductor" not in result["extras"]
    assert result["drawn"] is True


def test_material_refuses_malformed_extensions(session):
    """createCoatedConductorMaterial checks the extension object and names the field."""
    # Any example page will do: the one the test before left open (Cu at 1.8), no reload.
    page = session.example(session.fit("Cu", "coated-conductor"), 1.8)
    messages = page.evaluate("""async () => {
        const { checkModel } = await import('/static/three/index.js');
        const good = { kind: 'rgb-conductor', colorSpace: 'ACEScg', etaIRange: [1, 2.5],
                       coefficients: { n: [0.2, 0.5, 1.3], k: [3, 2.3, 1.9] } };
        const bad = [
            { ...good, kind: 'schlick' }, { ...good, colorSpace: 'sRGB' }, { ...good, coatIor: 1.5 },
            { ...good, coefficients: { n: [1, 1] , k: [0, 0, 0] } },
            { ...good, kind: 'coated-conductor', degree: 2, coefficients: { F0: [[1, 0, 0]], a: [], alpha: [] } },
            { ...good, kind: 'coated-conductor', degree: 5 },
        ];
        checkModel(good);
        checkModel(good, 2.9);
        const messages = bad.map((m) => { try { checkModel(m); return null; } catch (e) { return e.message; } });
        try { checkModel(good, 0.5); messages.push(null); } catch (e) { messages.push(e.message); }
        return messages;
    }""")
    assert all(messages), messages
    for message, field in zip(
        messages,
        ["`kind`", "`colorSpace`", "`coatIor`", "n > 0", "`coefficients.F0`", "`degree`", "`clearcoatIor`"],
        strict=True,
    ):
        assert field in message, message


# A 1 x 1 PNG (grey), the clear coat's factor and roughness textures.
PIXEL = (
    "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQ"
    "AAAABJRU5ErkJggg=="
)


def test_the_coat_is_the_clear_coats_textures_included(session):
    """
    The coat the model is drawn under is the material's KHR_materials_clearcoat
    as three loads it (factor, roughness and their textures), its index the
    nested KHR_materials_clearcoat_ior's: the shader compiles and draws with
    the coat's textures, and the exporter plugin writes them back with the index.
    """
    page = session.example(session.fit("Cu", "coated-conductor"), 1.8)
    clearcoat = {
        "clearcoatFactor": 0.8,
        "clearcoatTexture": {"index": 0},
        "clearcoatRoughnessFactor": 0.2,
        "clearcoatRoughnessTexture": {"index": 0},
        "extensions": {"KHR_materials_clearcoat_ior": {"clearcoatIor": 1.7}},
    }
    result = page.evaluate(
        """async ([model, clearcoat, pixel]) => {
        const THREE = await import('three');
        const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
        const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
        const { CoatedConductorExtension, CoatedConductorExporterExtension } = await import('/static/three/index.js');
        const json = { asset: { version: '2.0' },
                       extensionsUsed: ['EXT_materials_coated_conductor', 'KHR_materials_clearcoat',
                                        'KHR_materials_clearcoat_ior'],
                       images: [{ uri: pixel }], textures: [{ source: 0 }],
                       materials: [{ name: 'textured', pbrMetallicRoughness: { metallicFactor: 1 },
                                     extensions: { EXT_materials_coated_conductor: model,
                                                   KHR_materials_clearcoat: clearcoat } }] };
        const loader = new GLTFLoader();
        loader.register((parser) => new CoatedConductorExtension(parser));
        const gltf = await loader.parseAsync(JSON.stringify(json), '');
        const material = await gltf.parser.getDependency('material', 0);
        const renderer = new THREE.WebGLRenderer({ canvas: document.createElement('canvas') });
        renderer.setSize(32, 32);
        const scene = new THREE.Scene();
        const mesh = new THREE.Mesh(new THREE.SphereGeometry(1, 32, 16), material);
        scene.add(mesh);
        const white = new THREE.DataTexture(new Float32Array(16).fill(1), 2, 2, THREE.RGBAFormat, THREE.FloatType);
        white.mapping = THREE.EquirectangularReflectionMapping;
        white.needsUpdate = true;
        const pmrem = new THREE.PMREMGenerator(renderer);
        scene.environment = pmrem.fromEquirectangular(white).texture;
        const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 10);
        camera.position.set(0, 0, 4);
        const target = new THREE.WebGLRenderTarget(32, 32, { type: THREE.FloatType });
        renderer.setRenderTarget(target);
        renderer.render(scene, camera);
        const pixels = new Float32Array(4 * 32 * 32);
        renderer.readRenderTargetPixels(target, 0, 0, 32, 32, pixels);
        renderer.setRenderTarget(null);
        const centre = Array.from(pixels.slice(4 * (16 * 32 + 16), 4 * (16 * 32 + 16) + 3));
        const programs = renderer.info.programs.length;
        const exporter = new GLTFExporter();
        exporter.register((writer) => new CoatedConductorExporterExtension(writer));
        const written = await exporter.parseAsync(scene, { binary: false });
        renderer.dispose(); pmrem.dispose(); target.dispose();
        return { coatIor: material.userData.coatedConductor?.coatIor, clearcoat: material.clearcoat,
                 roughness: material.clearcoatRoughness, map: Boolean(material.clearcoatMap),
                 roughnessMap: Boolean(material.clearcoatRoughnessMap), centre, programs,
                 written: written.materials[0].extensions, used: written.extensionsUsed };
    }""",
        [GOOD_RGB, clearcoat, PIXEL],
    )
    assert result["coatIor"] == pytest.approx(1.7)
    assert result["clearcoat"] == pytest.approx(0.8) and result["roughness"] == pytest.approx(0.2)
    assert result["map"] and result["roughnessMap"]
    assert result["programs"] >= 1 and all(0.0 < c < 2.0 for c in result["centre"]), result["centre"]
    written = result["written"]["KHR_materials_clearcoat"]
    assert "clearcoatTexture" in written and "clearcoatRoughnessTexture" in written
    assert written["extensions"] == {"KHR_materials_clearcoat_ior": {"clearcoatIor": 1.7}}
    assert result["written"]["EXT_materials_coated_conductor"] == GOOD_RGB
    assert {"KHR_materials_clearcoat_ior", "EXT_materials_coated_conductor"} <= set(result["used"])
