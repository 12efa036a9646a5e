// The Babylon.js example of EXT_materials_coated_conductor: a fit's glTF
// export (GET /api/v1/fits/{id}/pack?format=gltf) loaded by Babylon's glTF
// loader with coated-conductor-babylon's extension, its material on a shader
// ball under a uniform white sky (radiance 1 in every direction: each pixel
// shows the coated metal's directional albedo), the camera of the three.js
// example (/examples/three.html) so that the two renders compare pixel by
// pixel. window.cfBabylon.readFloat reads the ball back as float radiance.

import { Engine } from "@babylonjs/core/Engines/engine.js";
import { Scene } from "@babylonjs/core/scene.js";
import { Color3, Color4 } from "@babylonjs/core/Maths/math.color.js";
import { SphericalPolynomial } from "@babylonjs/core/Maths/sphericalPolynomial.js";
import { Vector3 } from "@babylonjs/core/Maths/math.vector.js";
import { FreeCamera } from "@babylonjs/core/Cameras/freeCamera.js";
import { CreateSphere } from "@babylonjs/core/Meshes/Builders/sphereBuilder.js";
import { RawCubeTexture } from "@babylonjs/core/Materials/Textures/rawCubeTexture.js";
import { RenderTargetTexture } from "@babylonjs/core/Materials/Textures/renderTargetTexture.js";
import { Constants } from "@babylonjs/core/Engines/constants.js";
import { LoadAssetContainerAsync } from "@babylonjs/core/Loading/sceneLoader.js";
import "@babylonjs/loaders/glTF/index.js";
import { registerCoatedConductorExtension } from "/static/babylon/index.js";
import { orbitCamera } from "/static/preview.js";

const ORBIT = [0.5, 0.25, 4.2]; // the three.js example's
const FOV = 0.52; // radians, vertical

const query = new URLSearchParams(location.search);
const fitId = query.get("fit");
const etaI = Number(query.get("eta_i") ?? 1.5);

function say(text) {
  const status = document.getElementById("status");
  status.textContent = text;
  status.hidden = !text;
}

/**
 * A uniform sky of radiance 1 (linear), as a float cube map, with its
 * irradiance given (a constant spherical polynomial): Babylon mixes the
 * irradiance into the radiance of a rough lobe (MIX_IBL_RADIANCE_WITH_IRRADIANCE),
 * and would otherwise take it as 0 until it has read the cube back.
 */
function whiteSky(scene) {
  const face = new Float32Array(4 * 4 * 4).fill(1);
  const sky = new RawCubeTexture(scene, [face, face, face, face, face, face], 4,
    Constants.TEXTUREFORMAT_RGBA, Constants.TEXTURETYPE_FLOAT, false, false, Constants.TEXTURE_LINEAR_LINEAR);
  sky.gammaSpace = false;
  const irradiance = new SphericalPolynomial();
  irradiance.addAmbient(new Color3(1, 1, 1));
  sky.sphericalPolynomial = irradiance;
  return sky;
}

registerCoatedConductorExtension();
const engine = new Engine(document.getElementById("model"), false, { preserveDrawingBuffer: true, premultipliedAlpha: false });
const scene = new Scene(engine);
scene.useRightHandedSystem = true; // glTF's and three's handedness
scene.clearColor = new Color4(0, 0, 0, 0);
// Image processing "by post-process" and no post-process: the shader writes
// linear radiance (no tone mapping, no sRGB encoding), as three's float target holds.
scene.imageProcessingConfiguration.applyByPostProcess = true;
scene.environmentTexture = whiteSky(scene);
const { eye } = orbitCamera(ORBIT, FOV);
const camera = new FreeCamera("camera", new Vector3(...eye), scene);
camera.setTarget(Vector3.Zero());
camera.fov = FOV;
camera.minZ = 0.1;
camera.maxZ = 100;
const ball = CreateSphere("ball", { diameter: 2, segments: 128 }, scene);

// The fit `id`'s glTF export at `eta`, its material put on the ball.
async function loadFit(id, eta) {
  const url = `/api/v1/fits/${encodeURIComponent(id)}/pack?format=gltf&eta_i=${eta}`;
  const container = await LoadAssetContainerAsync(url, scene, { pluginExtension: ".gltf" });
  const material = container.materials.find((m) => m.pluginManager?.getPlugin("CoatedConductor"));
  if (!material) throw new Error("the export carries no EXT_materials_coated_conductor (eta_i outside the fit's range?)");
  const previous = ball.material;
  ball.material = material;
  previous?.dispose();
  const model = material.pluginManager.getPlugin("CoatedConductor").model;
  document.getElementById("material").textContent =
    `${material.name}: ${model.kind}, coat index ${material.pluginManager.getPlugin("CoatedConductor").coatIor}, metal roughness ${material.roughness}.`;
  await scene.whenReadyAsync();
  return model;
}

/**
 * Linear radiance (linear Rec.709) at width x height, RGBA floats, bottom
 * row first; alpha 0 off the ball. `settings`: {roughness, clearCoatRoughness}
 * set on the material first.
 */
async function readFloat(width, height, settings = {}) {
  if (settings.roughness !== undefined) ball.material.roughness = settings.roughness;
  if (settings.clearCoatRoughness !== undefined) ball.material.clearCoat.roughness = settings.clearCoatRoughness;
  const target = new RenderTargetTexture("read", { width, height }, scene,
    { type: Constants.TEXTURETYPE_FLOAT, generateMipMaps: false });
  target.renderList = [ball];
  target.activeCamera = camera;
  target.clearColor = new Color4(0, 0, 0, 0);
  await new Promise((resolve) => {
    const check = () => (ball.material.isReady(ball) ? resolve() : setTimeout(check, 20));
    check();
  });
  target.render();
  const pixels = await target.readPixels();
  target.dispose();
  return Array.from(new Float32Array(pixels.buffer, pixels.byteOffset, 4 * width * height));
}

async function main() {
  if (!fitId) throw new Error("no fit: open /examples/babylon.html?fit=ID");
  await loadFit(fitId, etaI);
  engine.runRenderLoop(() => scene.render());
  window.cfBabylon = {
    fit: { id: fitId, etaI },
    orbit: ORBIT,
    fov: FOV,
    readFloat,
    get material() { return ball.material; },
    setFit: async (id, eta) => { const model = await loadFit(id, eta); window.cfBabylon.fit = { id, etaI: eta }; return model; },
  };
  document.body.dataset.ready = "true";
}

main().catch((error) => {
  say(`Could not show the fit: ${error.message}`);
  document.body.dataset.ready = "false";
  console.error(error);
});
