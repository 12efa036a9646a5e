"""
The three.js package (web/three/, npm ``coated-conductor-three``) used as
a web developer uses it, with no service running: a folder laid out as npm
installs it (``node_modules/coated-conductor-three`` a copy of the package's
published files, ``node_modules/three`` the pinned three of scripts/three)
served by Python's http.server on 127.0.0.1, and a page that loads a glTF
export (Cu, coated-conductor kind, coat index 1.5, written in-process by
fitting.exports) through the package's GLTFLoader plugin and draws it on
the example page's shader ball under the white sky, three ways:

-   ``static``: the package imported by its path in the folder (three
    through an import map, as the package's peer dependency); every
    request the page makes is to a file of the folder: nothing is fetched
    from anywhere else (no /glsl/, no /api/);
-   ``importmap``: the package imported by its name through an import map;
-   ``bundler``: the same page script bundled by esbuild (pinned in
    web/three/package-lock.json) from the folder's node_modules through the
    package's ``exports``, no import map.

The three images are the same float for float, and each is the fit's own
model through the full air-coat-metal stack in numpy (tests/static/three_pages.py
``coated_albedo``) within the example page's bounds (test_three_material.py:
mean < 0.05 Delta E 2000, centre < 0.02), mirror and rough. The package's
types check: ``tsc --noEmit`` (pinned) on web/three/types-check/example.ts,
whose deliberate errors must be errors.

Cost: one folder, one esbuild run, one page a way (SwiftShader WebGL2,
128 x 128, two settings each), and one tsc run.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path
from urllib.parse import urlsplit

import numpy as np
import pytest
from editor_pages import _CHROMIUM, F32_BASE64, TIMEOUT_MS, camera_rays, from_f32
from three_pages import CENTRE, FOV, H, NDOTV_MIN, ORBIT, W, coated_albedo, fit_fresnel, per_pixel, serve

from fitting.colour.delta_e import delta_E_map
from fitting.exports import export_material
from fitting.fits.kinds import fit_model
from fitting.optics.library import library_material
from preview_shaders.display import ACEScg_to_sRGB_matrix

pytestmark = [pytest.mark.browser, pytest.mark.slow]

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "web" / "three"
THREE = ROOT / "scripts" / "three" / "node_modules" / "three"
ESBUILD = PACKAGE / "node_modules" / ".bin" / "esbuild"
TSC = PACKAGE / "node_modules" / ".bin" / "tsc"
ETA_I = 1.5
SETTINGS = [(0.0, 0.0), (0.3, 0.1)]  # (metal roughness, coat roughness)
PARITY_MEAN, PARITY_CENTRE = 0.05, 0.02

# The page's script: the example page's ball, camera and white sky
# (static/examples/three.js), the asset's material through the plugin;
# window.cfDraw(settings) renders into a float target, RGBA bottom row first.
SCENE = """
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { CoatedConductorExtension } from "PACKAGE";

const [yaw, pitch, distance] = ORBIT;
const renderer = new THREE.WebGLRenderer({ canvas: document.createElement("canvas"), antialias: false, alpha: true });
renderer.setClearColor(0x000000, 0);
const loader = new GLTFLoader();
loader.register((parser) => new CoatedConductorExtension(parser));
const gltf = await loader.loadAsync("coated.gltf");
let material = null;
gltf.scene.traverse((object) => { if (object.isMesh) material = object.material; });
const scene = new THREE.Scene();
scene.add(new THREE.Mesh(new THREE.SphereGeometry(1, 256, 128), material));
const white = new THREE.DataTexture(new Float32Array(16).fill(1), 2, 2, THREE.RGBAFormat, THREE.FloatType);
white.mapping = THREE.EquirectangularReflectionMapping;
white.needsUpdate = true;
const pmrem = new THREE.PMREMGenerator(renderer);
scene.environment = pmrem.fromEquirectangular(white).texture;
pmrem.dispose();
const camera = new THREE.PerspectiveCamera(THREE.MathUtils.radToDeg(FOV), WIDTH / HEIGHT, 0.1, 100);
camera.position.set(distance * Math.cos(pitch) * Math.sin(yaw), distance * Math.sin(pitch),
                    distance * Math.cos(pitch) * Math.cos(yaw));
camera.lookAt(0, 0, 0);
window.cfDraw = (settings) => {
  Object.assign(material, settings);
  const target = new THREE.WebGLRenderTarget(WIDTH, HEIGHT, { type: THREE.FloatType });
  renderer.setRenderTarget(target);
  renderer.render(scene, camera);
  const pixels = new Float32Array(4 * WIDTH * HEIGHT);
  renderer.readRenderTargetPixels(target, 0, 0, WIDTH, HEIGHT, pixels);
  renderer.setRenderTarget(null);
  target.dispose();
  return pixels;
};
window.cfModel = material.userData.coatedConductor?.model ?? null;
document.body.dataset.ready = "true";
"""

PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>coated-conductor-three: WAY</title>
<link rel="icon" href="data:,">IMPORTMAP
<script type="module" src="SCRIPT"></script></head><body></body></html>
"""


def import_map(entries: dict) -> str:
    return f'\n<script type="importmap">{json.dumps({"imports": entries})}</script>'


THREE_MAP = {
    "three": "./node_modules/three/build/three.module.js",
    "three/addons/": "./node_modules/three/examples/jsm/",
}


def scene(package: str) -> str:
    values = {"PACKAGE": package, "ORBIT": json.dumps(list(ORBIT)), "FOV": repr(FOV), "WIDTH": str(W), "HEIGHT": str(H)}
    text = SCENE
    for key, value in values.items():
        text = text.replace(key, value)
    return text


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The static folder: the package as npm installs it, three, the asset and the three pages; the extension object."""
    root = tmp_path_factory.mktemp("site")
    installed = root / "node_modules" / "coated-conductor-three"
    published = json.loads((PACKAGE / "package.json").read_text())["files"]
    installed.mkdir(parents=True)
    for name in ["package.json", *published]:
        source = PACKAGE / name.rstrip("/")
        if source.is_dir():
            shutil.copytree(source, installed / source.name)
        else:
            shutil.copy(source, installed / source.name)
    (root / "node_modules" / "three").symlink_to(THREE, target_is_directory=True)
    nk = library_material("Cu")
    document = export_material(nk, "gltf", ETA_I, model=fit_model(nk, (1.0, 2.5), "coated-conductor").packed)
    (root / "coated.gltf").write_bytes(document if isinstance(document, bytes) else document.encode())
    (root / "static.js").write_text(scene("./node_modules/coated-conductor-three/src/index.js"))
    (root / "static.html").write_text(
        PAGE.replace("WAY", "static").replace("IMPORTMAP", import_map(THREE_MAP)).replace("SCRIPT", "static.js")
    )
    (root / "importmap.js").write_text(scene("coated-conductor-three"))
    entries = {**THREE_MAP, "coated-conductor-three": "./node_modules/coated-conductor-three/src/index.js"}
    (root / "importmap.html").write_text(
        PAGE.replace("WAY", "importmap").replace("IMPORTMAP", import_map(entries)).replace("SCRIPT", "importmap.js")
    )
    done = subprocess.run(
        [str(ESBUILD), "importmap.js", "--bundle", "--format=esm", "--log-level=warning", "--outfile=bundle.js"],
        cwd=root,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    (root / "bundler.html").write_text(
        PAGE.replace("WAY", "bundler").replace("IMPORTMAP", "").replace("SCRIPT", "bundle.js")
    )
    extension = json.loads(document)["materials"][0]["extensions"]["EXT_materials_coated_conductor"]
    return root, extension


@pytest.fixture(scope="module")
def site(folder):
    """http.server on 127.0.0.1 serving the folder (and nothing else): its URL."""
    root, _ = folder
    with serve(root) as url:
        yield url


@pytest.fixture(scope="module")
def chromium():
    """The test process's one Chromium (editor_pages), without the service."""
    return _CHROMIUM.get()


@pytest.fixture(scope="module")
def images(chromium, site, folder):
    """way -> ({settings: (H, W, 4) float32 image, top row first}, the URLs it requested, errors, drawn model)."""
    root, _ = folder
    out = {}
    for way in ("static", "importmap", "bundler"):
        context = chromium.new_context(viewport={"width": 400, "height": 300})
        try:
            page = context.new_page()
            page.set_default_timeout(TIMEOUT_MS)
            requests, errors = [], []
            page.on("request", lambda request, requests=requests: requests.append(request.url))
            page.on(
                "response", lambda r, errors=errors: errors.append(f"{r.status} {r.url}") if r.status != 200 else None
            )
            page.on("pageerror", lambda error, errors=errors: errors.append(f"uncaught: {error}"))
            page.on(
                "console", lambda m, errors=errors: errors.append(f"console: {m.text}") if m.type == "error" else None
            )
            page.goto(f"{site}/{way}.html")
            page.wait_for_function("document.body.dataset.ready")
            drawn = {}
            for roughness, coat_roughness in SETTINGS:
                flat = page.evaluate(
                    f"(s) => {{ {F32_BASE64} return f32(window.cfDraw(s)); }}",
                    {"roughness": roughness, "clearcoatRoughness": coat_roughness},
                )
                drawn[roughness, coat_roughness] = from_f32(flat).reshape(H, W, 4)[::-1]
            out[way] = drawn, requests, errors, page.evaluate("window.cfModel")
        finally:
            context.close()
    return out


def test_static_folder_fetches_nothing_else(images, site, folder):
    """From the plain folder, the service stopped: only the folder's own files are requested, each found."""
    root, extension = folder
    _, requests, errors, model = images["static"]
    assert errors == [] and model == extension
    paths = [urlsplit(url).path for url in requests if not url.startswith("data:")]
    assert all(url.startswith(site + "/") for url in requests if not url.startswith("data:")), requests
    assert all((root / path.lstrip("/")).is_file() for path in paths), paths
    assert not [p for p in paths if p.startswith(("/glsl", "/api"))], paths
    # The package's own modules were loaded from the folder, the GLSL, kinds and LUT among them.
    assert {
        f"/node_modules/coated-conductor-three/src/generated/{name}" for name in ("lut.js", "glsl.js", "kinds.js")
    } <= set(paths)


@pytest.mark.parametrize("way", ["importmap", "bundler"])
def test_import_map_and_bundler_draw_the_same_image(images, folder, way):
    _, extension = folder
    drawn, requests, errors, model = images[way]
    assert errors == [] and model == extension
    if way == "bundler":  # one script: three and the package inside it
        scripts = [urlsplit(u).path for u in requests if u.endswith(".js")]
        assert scripts == ["/bundle.js"], scripts
    for settings, image in drawn.items():
        assert np.array_equal(image, images["static"][0][settings]), (way, settings)


def test_the_image_is_the_fit_through_the_full_stack(images, folder):
    """Each setting against the extension's own model composed with the air-coat-metal stack in numpy."""
    _, extension = folder
    fit = {"model": extension["kind"], "coefficients": extension["coefficients"], "eta_i_range": extension["etaIRange"]}
    NdotV, hit, _, _ = camera_rays(*ORBIT, FOV, W, H, bands=1)
    to_ACEScg = np.linalg.inv(ACEScg_to_sRGB_matrix()).T
    for (roughness, coat_roughness), image in images["static"][0].items():
        three, mask = image[..., :3] @ to_ACEScg, image[..., 3] > 0.5
        region = hit & mask & (NdotV >= NDOTV_MIN)
        composed = per_pixel(coated_albedo(fit_fresnel(fit, ETA_I), ETA_I, roughness, coat_roughness), NdotV)
        dE = delta_E_map(composed, three)
        assert region.sum() > 10_000
        assert dE[region].mean() < PARITY_MEAN, (roughness, dE[region].mean())
        assert dE[region & (NdotV >= CENTRE)].mean() < PARITY_CENTRE, (roughness, dE[region & (NdotV >= CENTRE)].mean())


def test_types_check():
    """tsc --noEmit on the example: the API's types resolve through the package's exports and reject misuse."""
    done = subprocess.run(
        [str(TSC), "--noEmit", "-p", str(PACKAGE / "types-check")],
        cwd=PACKAGE,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
