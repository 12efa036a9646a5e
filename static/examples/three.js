// The three.js example page (/examples/three.html?fit=ID): a stored fit's
// glTF export (GET /api/v1/fits/{id}/pack?format=gltf) loaded twice, once
// with the CoatedConductorExtension plugin and once without (the fallback
// every glTF viewer draws), each material on the same shader ball, camera
// and environment as the editor's preview (static/preview.js: orbit
// (0.5, 0.25, 4.2), vertical field of view 0.52 rad). The asset's material
// goes on a finer sphere than the asset's own 24 x 12 one, so that the ball
// is round to the pixel. One WebGLRenderer (one GL context, off the page)
// draws both balls, so that an environment is prefiltered (three's PMREM)
// once and both scenes share it; each ball's canvas shows a copy of its
// image. `window.cfThree` renders either into a float target for the parity
// tests; `setEnvironment(name)` relights both balls and `setFit(id, etaI)`
// puts another fit's export on them, neither with a reload, and each
// environment is prefiltered once a page (three's PMREM, the page's slowest
// step in SwiftShader).

import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { RoomEnvironment } from "three/addons/environments/RoomEnvironment.js";
import { CoatedConductorExtension } from "/static/three/index.js";
import { loadIncludes } from "/static/glsl.js";
import { orbitCamera } from "/static/preview.js";

const ORBIT = [0.5, 0.25, 4.2];
const FOV = 0.52; // radians, vertical

const query = new URLSearchParams(location.search);
const fitId = query.get("fit");
const etaI = Number(query.get("eta_i") ?? 1.5);
const environmentName = query.get("env") ?? "room";

function say(text) {
  const status = document.getElementById("status");
  status.textContent = text;
  status.hidden = !text;
}

async function loadMaterial(url, withPlugin) {
  const loader = new GLTFLoader();
  if (withPlugin) loader.register((parser) => new CoatedConductorExtension(parser));
  const gltf = await loader.loadAsync(url);
  let material = null;
  gltf.scene.traverse((object) => { if (object.isMesh) material = object.material; });
  if (!material) throw new Error("the asset has no mesh");
  return material;
}

// The preview's environments (cf_environment.glsl: CF_ENVIRONMENT_* is
// the index in static/splitsum.js ENVIRONMENT_NAMES), drawn by the
// project's own GLSL into an equirect in three's convention (u from
// atan(z, x), v from asin(y), v = 1 up) in three's working space (linear
// Rec.709, CF_ACESCG_TO_SRGB of cf_display.glsl), EQUIRECT_W x EQUIRECT_W / 2.
const PREVIEW_ENVIRONMENTS = { white_sky: 0, studio: 1, outdoor: 2 };
const EQUIRECT_W = 1024;

async function previewEquirect(renderer, index) {
  const glsl = await loadIncludes(["cf_environment.glsl", "cf_display.glsl"]);
  const material = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3,
    vertexShader: "in vec3 position;\nvoid main() { gl_Position = vec4(position.xy, 0.0, 1.0); }",
    fragmentShader: `precision highp float;\nprecision highp int;\n${glsl}
uniform int u_environment;
uniform vec2 u_size;
out vec4 out_radiance;
void main()
{
    vec2 uv = gl_FragCoord.xy / u_size;
    float phi = (uv.x - 0.5) * 6.283185307179586;
    float lat = (uv.y - 0.5) * 3.141592653589793;
    vec3 d = vec3(cos(phi) * cos(lat), sin(lat), sin(phi) * cos(lat));
    // Linear ACEScg to three's working space, linear Rec.709 (as the material's terms).
    out_radiance = vec4(CF_ACESCG_TO_SRGB * cf_environment(u_environment, d), 1.0);
}`,
    uniforms: { u_environment: { value: index }, u_size: { value: new THREE.Vector2(EQUIRECT_W, EQUIRECT_W / 2) } },
    depthTest: false, depthWrite: false,
  });
  const target = new THREE.WebGLRenderTarget(EQUIRECT_W, EQUIRECT_W / 2, { type: THREE.FloatType, depthBuffer: false });
  const scene = new THREE.Scene();
  const quad = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material);
  quad.frustumCulled = false;
  scene.add(quad);
  renderer.setRenderTarget(target);
  renderer.render(scene, new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1));
  renderer.setRenderTarget(null);
  quad.geometry.dispose();
  material.dispose();
  target.texture.mapping = THREE.EquirectangularReflectionMapping;
  return target;
}

// The environment `name`: three's RoomEnvironment ("room"), the white sky
// (radiance 1 in every direction) or the preview's studio or outdoor sky
// (the project's GLSL), prefiltered by three's PMREM.
async function environment(renderer, name) {
  const pmrem = new THREE.PMREMGenerator(renderer);
  let target;
  if (name === "studio" || name === "outdoor") {
    const equirect = await previewEquirect(renderer, PREVIEW_ENVIRONMENTS[name]);
    target = pmrem.fromEquirectangular(equirect.texture);
    equirect.dispose();
  } else if (name === "white_sky") {
    const white = new THREE.DataTexture(new Float32Array([1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1]), 2, 2,
      THREE.RGBAFormat, THREE.FloatType);
    white.mapping = THREE.EquirectangularReflectionMapping;
    white.needsUpdate = true;
    target = pmrem.fromEquirectangular(white);
  } else {
    target = pmrem.fromScene(new RoomEnvironment(), 0.04);
  }
  pmrem.dispose();
  return target.texture;
}

class Ball {
  constructor(renderer, canvas, material) {
    this.canvas = canvas;
    this.renderer = renderer;
    this.scene = new THREE.Scene();
    this.material = material;
    // 256 x 128 segments: the polygon strays from the sphere by at most 8e-5 of its radius (1 - cos(pi / 256)),
    // 0.01 px on this page's 384 px canvas; 512 x 256 drew 4 times the triangles for nothing a pixel shows.
    this.mesh = new THREE.Mesh(new THREE.SphereGeometry(1, 256, 128), material);
    this.scene.add(this.mesh);
    const { eye } = orbitCamera(ORBIT, FOV);
    this.camera = new THREE.PerspectiveCamera(THREE.MathUtils.radToDeg(FOV), 1, 0.1, 100);
    this.camera.position.set(...eye);
    this.camera.lookAt(0, 0, 0);
  }

  /** Draw `material` from now on; the one before it is disposed (and the plugin's table with it). */
  setMaterial(material) {
    const before = this.material;
    this.material = material;
    this.mesh.material = material;
    before.userData.coatedConductor?.dispose?.();
    before.dispose();
  }

  /** Draw into the shared renderer at the canvas's size and copy the image to the canvas. */
  draw() {
    const width = this.canvas.clientWidth, height = this.canvas.clientHeight;
    this.renderer.setPixelRatio(1);
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.renderer.render(this.scene, this.camera);
    this.canvas.width = width;
    this.canvas.height = height;
    this.canvas.getContext("2d").drawImage(this.renderer.domElement, 0, 0);
  }

  /**
   * Linear radiance (three's working space, linear Rec.709) at width x
   * height, RGBA floats, bottom row first; alpha 0 off the ball.
   * `settings`: {roughness, clearcoatRoughness} set on the material first.
   */
  readFloat(width, height, settings = {}) {
    Object.assign(this.material, settings);
    const target = new THREE.WebGLRenderTarget(width, height, { type: THREE.FloatType });
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.renderer.setRenderTarget(target);
    this.renderer.render(this.scene, this.camera);
    const pixels = new Float32Array(4 * width * height);
    this.renderer.readRenderTargetPixels(target, 0, 0, width, height, pixels);
    this.renderer.setRenderTarget(null);
    target.dispose();
    return Array.from(pixels);
  }
}

// The fit `id`'s glTF export at `eta`, loaded with the plugin (model) and without (fallback).
async function loadFit(id, eta) {
  const url = `/api/v1/fits/${encodeURIComponent(id)}/pack?format=gltf&eta_i=${eta}`;
  const [model, fallback] = await Promise.all([loadMaterial(url, true), loadMaterial(url, false)]);
  const info = model.userData.coatedConductor;
  if (!info) throw new Error("the export carries no EXT_materials_coated_conductor (eta_i outside the fit's range?)");
  document.getElementById("material").textContent =
    `${model.name}: ${info.model.kind}, coat index ${info.coatIor}, metal roughness ${model.roughness}, coat roughness ${model.clearcoatRoughness}.`;
  return { model, fallback };
}

async function main() {
  if (!fitId) throw new Error("no fit: open /examples/three.html?fit=ID");
  const { model, fallback } = await loadFit(fitId, etaI);
  const renderer = new THREE.WebGLRenderer({
    canvas: document.createElement("canvas"), antialias: false, preserveDrawingBuffer: true, alpha: true,
  });
  renderer.setClearColor(0x000000, 0);
  const balls = {
    model: new Ball(renderer, document.getElementById("model"), model),
    fallback: new Ball(renderer, document.getElementById("fallback"), fallback),
  };
  const environments = new Map(); // name -> Promise of its PMREM texture, both scenes', kept for the page's life
  const light = async (name) => {
    if (!environments.has(name)) {
      const made = environment(renderer, name);
      environments.set(name, made);
      made.catch(() => environments.delete(name)); // a failed one is tried again next time
    }
    const texture = await environments.get(name);
    for (const ball of Object.values(balls)) ball.scene.environment = texture;
    for (const ball of Object.values(balls)) ball.draw();
    if (window.cfThree) window.cfThree.environment = name;
  };
  await light(environmentName);
  window.cfThree = {
    balls,
    orbit: ORBIT,
    fov: FOV,
    readFloat: (which, width, height, settings) => balls[which].readFloat(width, height, settings),
    readTable: () => balls.model.material.userData.coatedConductor.readTable(renderer), // the fit on screen
    // Relight both balls (room, white_sky, studio, outdoor) without reloading the asset.
    setEnvironment: light,
    environment: environmentName,
    // Another fit's export (its id, at coat index etaI) on both balls, without reloading the page.
    setFit: async (id, eta) => {
      const next = await loadFit(id, eta);
      balls.model.setMaterial(next.model);
      balls.fallback.setMaterial(next.fallback);
      for (const ball of Object.values(balls)) ball.draw();
      window.cfThree.fit = { id, etaI: eta };
    },
    fit: { id: fitId, etaI },
  };
  document.body.dataset.ready = "true";
}

main().catch((error) => {
  say(`Could not draw the fit: ${error.message}`);
  document.body.dataset.ready = "error";
  console.error(error);
});
