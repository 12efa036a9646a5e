"""
The three.js package's two paths on one page, for
tests/static/test_three_node_material.py and benchmarks/three_node_parity.py:
a static folder laid out as npm installs the package (three the pinned
copy of scripts/three) whose page draws one extension object on the
package test's shader ball under the white sky (test_three_package.py's
scene) twice, with ``WebGLRenderer`` and the package's material, and with
``WebGPURenderer`` and the package's node material
(``coated-conductor-three/webgpu``); headless Chromium has no WebGPU
adapter, so the WebGPURenderer runs its WebGL2 backend (``forceWebGL``:
the same on every machine). Both images are read back as float radiance
(linear Rec.709), top row first; :func:`parity` gives the mean, 99th
percentile and max Delta E 2000 between them over the ball's pixels with
NdotV >= 0.1.
"""

from __future__ import annotations

import json
import shutil
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from editor_pages import F32_BASE64, TIMEOUT_MS, camera_rays, from_f32
from three_pages import FOV, H, NDOTV_MIN, ORBIT, W

from fitting.colour.delta_e import delta_E_map
from preview_shaders.display import ACEScg_to_sRGB_matrix

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "web" / "three"
THREE = ROOT / "scripts" / "three" / "node_modules" / "three"

SCRIPT = """
import * as THREE from "three";
import { PMREMGenerator as NodePMREMGenerator, RenderTarget, WebGPURenderer } from "three/webgpu";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { CoatedConductorExtension, createCoatedConductorMaterial } from "coated-conductor-three";
import { createCoatedConductorNodeMaterial, useCoatedConductorNodeMaterials } from "coated-conductor-three/webgpu";

const [yaw, pitch, distance] = ORBIT;
const camera = new THREE.PerspectiveCamera(THREE.MathUtils.radToDeg(FOV), WIDTH / HEIGHT, 0.1, 100);
camera.position.set(distance * Math.cos(pitch) * Math.sin(yaw), distance * Math.sin(pitch),
                    distance * Math.cos(pitch) * Math.cos(yaw));
camera.lookAt(0, 0, 0);
const white = new THREE.DataTexture(new Float32Array(16).fill(1), 2, 2, THREE.RGBAFormat, THREE.FloatType);
white.mapping = THREE.EquirectangularReflectionMapping;
white.needsUpdate = true;
const sphere = new THREE.SphereGeometry(1, 256, 128);

const gl = new THREE.WebGLRenderer({ canvas: document.createElement("canvas"), antialias: false, alpha: true });
gl.setClearColor(0x000000, 0);
const glScene = new THREE.Scene();
const glPmrem = new THREE.PMREMGenerator(gl);
glScene.environment = glPmrem.fromEquirectangular(white).texture;
glPmrem.dispose();

const gpu = new WebGPURenderer({ canvas: document.createElement("canvas"), antialias: false, alpha: true,
                                 forceWebGL: true });
await gpu.init();
gpu.setClearColor(0x000000, 0);
const gpuScene = new THREE.Scene();
gpuScene.environment = new NodePMREMGenerator(gpu).fromEquirectangular(white).texture;

async function drawGL(material) {
  const mesh = new THREE.Mesh(sphere, material);
  glScene.add(mesh);
  const target = new THREE.WebGLRenderTarget(WIDTH, HEIGHT, { type: THREE.FloatType });
  gl.setRenderTarget(target);
  gl.render(glScene, camera);
  const pixels = new Float32Array(4 * WIDTH * HEIGHT);
  gl.readRenderTargetPixels(target, 0, 0, WIDTH, HEIGHT, pixels);
  gl.setRenderTarget(null);
  target.dispose();
  glScene.remove(mesh);
  return pixels;
}

async function drawNode(material) {
  const mesh = new THREE.Mesh(sphere, material);
  gpuScene.add(mesh);
  const target = new RenderTarget(WIDTH, HEIGHT, { type: THREE.FloatType });
  gpu.setRenderTarget(target);
  gpu.render(gpuScene, camera);
  const pixels = await gpu.readRenderTargetPixelsAsync(target, 0, 0, WIDTH, HEIGHT);
  gpu.setRenderTarget(null);
  target.dispose();
  gpuScene.remove(mesh);
  return new Float32Array(pixels);
}

// A white directional light over the camera's right shoulder, in both scenes when `lit`.
const lights = [glScene, gpuScene].map((scene) => {
  const light = new THREE.DirectionalLight(0xffffff, 2);
  light.position.set(3, 4, 5);
  light.visible = false;
  scene.add(light);
  return light;
});

// Both images of extension object `model` at {roughness, clearcoatRoughness}: [WebGL, node], RGBA bottom row first.
window.cfDrawBoth = async (model, settings, lit) => {
  for (const light of lights) light.visible = lit;
  const glMaterial = await createCoatedConductorMaterial({ model, ...settings });
  const nodeMaterial = await createCoatedConductorNodeMaterial({ model, ...settings });
  const images = [await drawGL(glMaterial), await drawNode(nodeMaterial)];
  glMaterial.userData.coatedConductor.dispose();
  glMaterial.dispose();
  nodeMaterial.dispose();
  return images;
};
// Two extension objects' materials, each at its settings, made before either is drawn (alive together,
// as in one scene): [WebGL a, node a, WebGL b, node b].
window.cfDrawPair = async (a, b, settings) => {
  const gl = await Promise.all([a, b].map((model, i) => createCoatedConductorMaterial({ model, ...settings[i] })));
  const node = await Promise.all([a, b].map((model, i) => createCoatedConductorNodeMaterial({ model, ...settings[i] })));
  const images = [await drawGL(gl[0]), await drawNode(node[0]), await drawGL(gl[1]), await drawNode(node[1])];
  for (const material of gl) material.userData.coatedConductor.dispose();
  for (const material of [...gl, ...node]) material.dispose();
  return images;
};

// The glTF at `url` through the loader plugin, its material at `settings` drawn as loaded (WebGL) and
// after useCoatedConductorNodeMaterials (node): [WebGL, node, whether the node one is the package's].
window.cfDrawGltf = async (url, settings, lit) => {
  for (const light of lights) light.visible = lit;
  const loader = new GLTFLoader();
  loader.register((parser) => new CoatedConductorExtension(parser));
  const gltf = await loader.loadAsync(url);
  let material = null;
  gltf.scene.traverse((object) => { if (object.isMesh) material = object.material; });
  Object.assign(material, settings);
  const holder = new THREE.Mesh(sphere, material);
  await useCoatedConductorNodeMaterials(holder);
  return [await drawGL(material), await drawNode(holder.material), holder.material.isCoatedConductorNodeMaterial === true];
};
window.cfBackend = gpu.backend.isWebGLBackend ? "WebGL2" : "WebGPU";
document.body.dataset.ready = "true";
"""

PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>coated-conductor-three: WebGL and node material</title>
<link rel="icon" href="data:,">
<script type="importmap">IMPORTS</script>
<script type="module" src="parity.js"></script></head><body></body></html>
"""

IMPORTS = {
    "three": "./node_modules/three/build/three.module.js",
    "three/webgpu": "./node_modules/three/build/three.webgpu.js",
    "three/tsl": "./node_modules/three/build/three.tsl.js",
    "three/addons/": "./node_modules/three/examples/jsm/",
    "coated-conductor-three": "./node_modules/coated-conductor-three/src/index.js",
    "coated-conductor-three/webgpu": "./node_modules/coated-conductor-three/src/node_material.js",
}


def write_folder(root: Path) -> None:
    """The package as npm installs it (its published files), three, the page and its script under ``root``."""
    installed = root / "node_modules" / "coated-conductor-three"
    installed.mkdir(parents=True)
    for name in ["package.json", *json.loads((PACKAGE / "package.json").read_text())["files"]]:
        source = PACKAGE / name.rstrip("/")
        if source.is_dir():
            shutil.copytree(source, installed / source.name)
        else:
            shutil.copy(source, installed / source.name)
    (root / "node_modules" / "three").symlink_to(THREE, target_is_directory=True)
    values = {"ORBIT": json.dumps(list(ORBIT)), "FOV": repr(FOV), "WIDTH": str(W), "HEIGHT": str(H)}
    script = SCRIPT
    for key, value in values.items():
        script = script.replace(key, value)
    (root / "parity.js").write_text(script)
    (root / "parity.html").write_text(PAGE.replace("IMPORTS", json.dumps({"imports": IMPORTS})))


@contextmanager
def parity_page(chromium, site: str):
    """The page, ready: (page, errors seen so far, the WebGPURenderer's backend)."""
    context = chromium.new_context(viewport={"width": 400, "height": 300})
    try:
        page = context.new_page()
        page.set_default_timeout(TIMEOUT_MS)
        errors: list[str] = []
        page.on("pageerror", lambda error: errors.append(f"uncaught: {error}"))
        page.on("console", lambda m: errors.append(f"console: {m.text}") if m.type == "error" else None)
        page.goto(f"{site}/parity.html")
        page.wait_for_function("document.body.dataset.ready || document.body.dataset.failed")
        yield page, errors, page.evaluate("window.cfBackend")
    finally:
        context.close()


def draw_both(page, model: dict, roughness: float, coat_roughness: float, lit: bool = False, coat_ior: float = 1.5):
    """
    (WebGL, node material) images of extension object ``model`` under a
    clear coat of index ``coat_ior``, under the white sky (and with ``lit`` a directional light): (H, W, 4) float
    radiance, top row first.
    """
    flat = page.evaluate(
        f"async ([m, s, l]) => {{ {F32_BASE64} const [a, b] = await window.cfDrawBoth(m, s, l); return [f32(a), f32(b)]; }}",
        [model, {"roughness": roughness, "clearcoatRoughness": coat_roughness, "coatIor": coat_ior}, lit],
    )
    return tuple(from_f32(text).reshape(H, W, 4)[::-1] for text in flat)


def draw_gltf(page, url: str, roughness: float, coat_roughness: float, lit: bool = False):
    """(WebGL, node material, whether the node one is the package's) of the glTF at ``url`` (see :func:`draw_both`)."""
    a, b, twin = page.evaluate(
        f"async ([u, s, l]) => {{ {F32_BASE64} const [a, b, t] = await window.cfDrawGltf(u, s, l); "
        "return [f32(a), f32(b), t]; }",
        [url, {"roughness": roughness, "clearcoatRoughness": coat_roughness}, lit],
    )
    return *(from_f32(text).reshape(H, W, 4)[::-1] for text in (a, b)), twin


def draw_pair(page, a: tuple[dict, float], b: tuple[dict, float], roughness: float, coat_roughness: float):
    """
    (WebGL a, node a, WebGL b, node b) of ``a`` and ``b``, each (extension
    object, coat index): both materials made before either is drawn.
    """
    settings = [{"roughness": roughness, "clearcoatRoughness": coat_roughness, "coatIor": eta} for _, eta in (a, b)]
    flat = page.evaluate(
        f"async ([a, b, s]) => {{ {F32_BASE64} return (await window.cfDrawPair(a, b, s)).map(f32); }}",
        [a[0], b[0], settings],
    )
    return [from_f32(text).reshape(H, W, 4)[::-1] for text in flat]


def parity(webgl: np.ndarray, node: np.ndarray) -> dict:
    """Delta E 2000 between the two images over the ball (both drawn, NdotV >= 0.1): mean, p99, max, pixels."""
    NdotV, hit, _, _ = camera_rays(*ORBIT, FOV, W, H, bands=1)
    region = hit & (webgl[..., 3] > 0.5) & (node[..., 3] > 0.5) & (NdotV >= NDOTV_MIN)
    to_ACEScg = np.linalg.inv(ACEScg_to_sRGB_matrix()).T
    dE = delta_E_map(webgl[..., :3] @ to_ACEScg, node[..., :3] @ to_ACEScg)[region]
    return {
        "mean": float(dE.mean()),
        "p99": float(np.percentile(dE, 99)),
        "max": float(dE.max()),
        "pixels": int(region.sum()),
    }
