// "Your scene": the fit on screen drawn by three.js on the artist's own
// mesh (.glb) under their own environment (.hdr or .exr), beside the shader ball.
// The material is the fit's glTF export at the preview's settings (coat
// index, metal and coat roughness) loaded through the project's three.js
// package (/static/three/, EXT_materials_coated_conductor), so it is the
// model through the whole air / coat / metal stack, as in any three.js
// scene. Until a file is chosen, the scene is a sphere under three's
// RoomEnvironment. Files are read in the page (three's GLTFLoader,
// HDRLoader and EXRLoader); nothing is sent to the server, and three is
// the service's own pinned copy (/vendor/three/). Drag to orbit, wheel to
// zoom (three's OrbitControls). three is loaded when the view is first
// opened, never on the editor's start.

import { domain, packURL } from "../api.js";

const $ = (id) => document.getElementById(id);

export const SCENE_LIMIT_BYTES = 64 * 1024 * 1024;
const LIMIT_TEXT = "64 MB";

// The export a glTF loader reads: the registry's format of glTF's JSON media type (GET /domain).
const GLTF_MEDIA_TYPE = "model/gltf+json";
async function gltfFormat() {
  const format = (await domain()).export_formats.find((f) => f.media_type === GLTF_MEDIA_TYPE);
  if (!format) throw new Error(`the service lists no export of media type ${GLTF_MEDIA_TYPE}`);
  return format.name;
}

/**
 * Check that an OpenEXR file's header lies whole inside the file: its
 * attributes (name, type, size, value; the channels' names of a chlist)
 * walked with every read bounded, part after part for a multi-part file.
 * Throws for a header cut short. three's EXRLoader reads each name up to
 * its null byte with no bound, so a file cut inside its header would keep
 * the page busy for ever: it is handed only a header that ends.
 */
export function checkExrHeader(buffer) {
  const bytes = new Uint8Array(buffer), view = new DataView(buffer);
  const fail = (why) => { throw new Error(`its header ${why}`); };
  if (bytes.length < 8 || view.getUint32(0, true) !== 20000630) fail("has no OpenEXR magic number");
  let at = 8;
  const name = (end) => {
    const zero = bytes.indexOf(0, at);
    if (zero < 0 || zero >= end) fail("ends inside a name (the file is cut short)");
    const empty = zero === at;
    at = zero + 1;
    return empty;
  };
  for (;;) {
    let attributes = 0;
    while (!name(bytes.length)) {
      name(bytes.length); // the attribute's type
      if (at + 4 > bytes.length) fail("ends inside an attribute (the file is cut short)");
      const size = view.getUint32(at, true), start = at + 4, end = start + size;
      if (end > bytes.length) fail("ends inside an attribute (the file is cut short)");
      const type = new TextDecoder().decode(bytes.subarray(bytes.lastIndexOf(0, at - 2) + 1, at - 1));
      for (at = start; type === "chlist" && at < end - 1; at += 16) name(end); // name, then 16 bytes a channel
      at = end;
      attributes += 1;
    }
    if (!(bytes[5] & 16) || attributes === 0) return; // one part, or the empty header after a multi-part's last
  }
}

export class SceneView {
  /** settings(): {etaI, roughness, coatRoughness}, the preview's. */
  constructor(settings) {
    this.settings = settings;
    this.fit = null;
    this.three = null; // the loaded modules and scene, once opened
    this.materialFor = null; // the URL of the export on the mesh
    $("scene").addEventListener("toggle", () => { if ($("scene").open) this.#open().catch((e) => this.#say(e)); });
    $("scene-mesh").addEventListener("change", () => this.#upload("mesh").catch((e) => this.#say(e)));
    $("scene-environment").addEventListener("change", () => this.#upload("environment").catch((e) => this.#say(e)));
    $("scene-default").addEventListener("click", () => this.#builtIn().catch((e) => this.#say(e)));
  }

  /** The fit on screen (drawn now if the view is open). */
  showFit(fit) {
    this.fit = fit;
    this.refresh();
  }

  /** The preview's settings changed (eta_i, roughness): the export again. */
  refresh() {
    if (this.three) this.#material().catch((e) => this.#say(e));
  }

  #say(error, text = null) {
    const box = $("scene-status");
    box.textContent = text ?? `Could not draw your scene: ${error.message}`;
    box.classList.toggle("error", Boolean(error));
    $("scene").dataset.state = error ? "error" : "ready";
    if (error) console.warn(error);
  }

  async #open() {
    if (this.opening) return this.opening;
    this.opening = (async () => {
      const [THREE, { GLTFLoader }, { HDRLoader }, { EXRLoader }, { OrbitControls }, { RoomEnvironment }, plugin] =
      await Promise.all([
        import("three"), import("three/addons/loaders/GLTFLoader.js"), import("three/addons/loaders/HDRLoader.js"),
        import("three/addons/loaders/EXRLoader.js"),
        import("three/addons/controls/OrbitControls.js"), import("three/addons/environments/RoomEnvironment.js"),
        import("/static/three/index.js"),
      ]);
      const canvas = $("scene-canvas");
      const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true, alpha: true });
      renderer.setClearColor(0x000000, 0);
      renderer.toneMapping = THREE.NoToneMapping;
      const scene = new THREE.Scene();
      const camera = new THREE.PerspectiveCamera(30, 1, 0.01, 100);
      camera.position.set(2.0, 1.1, 3.6);
      const controls = new OrbitControls(camera, canvas);
      controls.minDistance = 1.2;
      controls.maxDistance = 20;
      const pmrem = new THREE.PMREMGenerator(renderer);
      const room = pmrem.fromScene(new RoomEnvironment(), 0.04).texture;
      const group = new THREE.Group();
      scene.add(group);
      this.three = { THREE, GLTFLoader, HDRLoader, EXRLoader, plugin, renderer, scene, camera, controls, pmrem, room, group,
                     material: null, meshName: "sphere", environmentName: "room (built in)" };
      controls.addEventListener("change", () => this.draw());
      new ResizeObserver(() => this.draw()).observe(canvas);
      window.cfScene = this; // for the tests
      await this.#builtIn();
    })();
    return this.opening;
  }

  /** The built-in sphere under three's RoomEnvironment. */
  async #builtIn() {
    const t = this.three;
    if (!t) return;
    this.#setObject(new t.THREE.Mesh(new t.THREE.SphereGeometry(1, 128, 64)), "sphere");
    this.#setEnvironment(t.room, "room (built in)");
    $("scene-mesh").value = "";
    $("scene-environment").value = "";
    await this.#material();
  }

  // An uploaded file, read in the page: the mesh (.glb) or the environment (.hdr or .exr).
  async #upload(which) {
    const input = $(which === "mesh" ? "scene-mesh" : "scene-environment");
    const file = input.files[0];
    if (!file) return;
    await this.#open();
    const expected = which === "mesh" ? [".glb"] : [".hdr", ".exr"];
    const extension = expected.find((name) => file.name.toLowerCase().endsWith(name));
    if (!extension) {
      const text = expected.join(" or ");
      throw new Error(`${file.name} is not a ${text} file (the ${which} must be ${text})`);
    }
    if (file.size > SCENE_LIMIT_BYTES) {
      throw new Error(`${file.name} is ${(file.size / 1048576).toFixed(0)} MB; the ${which} may be at most ${LIMIT_TEXT}`);
    }
    $("scene").dataset.state = "loading";
    const t = this.three;
    const buffer = await file.arrayBuffer();
    if (which === "mesh") {
      const gltf = await new Promise((resolve, reject) =>
        new t.GLTFLoader().parse(buffer, "", resolve, (error) => reject(new Error(`not a readable glTF binary: ${error.message ?? error}`))));
      let meshes = 0;
      gltf.scene.traverse((object) => { if (object.isMesh) meshes += 1; });
      if (!meshes) throw new Error(`${file.name} has no mesh`);
      this.#setObject(gltf.scene, file.name);
    } else {
      // Either decoder gives linear RGBA at half float (EXRLoader: its channels as RGBA, alpha 1 where absent).
      const [Loader, what] = extension === ".exr" ? [t.EXRLoader, "OpenEXR .exr"] : [t.HDRLoader, "Radiance .hdr"];
      let data;
      try {
        if (extension === ".exr") checkExrHeader(buffer);
        data = new Loader().parse(buffer);
      } catch (error) {
        throw new Error(`${file.name} is not a readable ${what}: ${error.message}`);
      }
      const texture = new t.THREE.DataTexture(data.data, data.width, data.height, t.THREE.RGBAFormat, data.type);
      texture.mapping = t.THREE.EquirectangularReflectionMapping;
      texture.colorSpace = t.THREE.LinearSRGBColorSpace;
      texture.minFilter = texture.magFilter = t.THREE.LinearFilter;
      texture.generateMipmaps = false;
      texture.needsUpdate = true;
      const target = t.pmrem.fromEquirectangular(texture);
      texture.dispose();
      this.#setEnvironment(target.texture, file.name);
    }
    this.#applyMaterial();
    this.#ready();
  }

  // Put `object` in the scene, centred and scaled to the unit sphere; the camera framed on it.
  #setObject(object, name) {
    const t = this.three;
    for (const child of [...t.group.children]) t.group.remove(child);
    const box = new t.THREE.Box3().setFromObject(object);
    const sphere = box.getBoundingSphere(new t.THREE.Sphere());
    const scale = sphere.radius > 0 ? 1 / sphere.radius : 1;
    object.scale.multiplyScalar(scale);
    object.position.sub(sphere.center.multiplyScalar(scale));
    t.group.add(object);
    t.meshName = name;
    t.controls.target.set(0, 0, 0);
    t.controls.update();
  }

  #setEnvironment(texture, name) {
    const t = this.three;
    if (t.scene.environment && t.scene.environment !== t.room) t.scene.environment.dispose();
    t.scene.environment = texture;
    t.environmentName = name;
  }

  // The fit's glTF export at the preview's settings, through the package's plugin, on every mesh.
  async #material() {
    const t = this.three;
    if (!t || !this.fit) return;
    const url = packURL(this.fit.id, await gltfFormat(), this.settings());
    if (!this.fit) return;
    if (url === this.materialFor && t.material) return this.#ready();
    this.materialFor = url;
    $("scene").dataset.state = "loading";
    const loader = new t.GLTFLoader();
    loader.register((parser) => new t.plugin.CoatedConductorExtension(parser));
    const gltf = await loader.loadAsync(url);
    if (url !== this.materialFor) return; // a later fit or setting since
    let material = null;
    gltf.scene.traverse((object) => { if (object.isMesh && !material) material = object.material; });
    if (!material || !material.userData.coatedConductor) {
      throw new Error("the fit's export carries no coated-conductor material at this coat index");
    }
    const before = t.material;
    t.material = material;
    this.#applyMaterial();
    if (before) {
      before.userData.coatedConductor?.dispose?.();
      before.dispose();
    }
    this.#ready();
  }

  #applyMaterial() {
    const t = this.three;
    if (!t.material) return;
    t.group.traverse((object) => { if (object.isMesh) object.material = t.material; });
  }

  /** Draw at the canvas's size. */
  draw() {
    const t = this.three;
    if (!t || !t.material) return;
    const canvas = t.renderer.domElement;
    const width = Math.max(1, canvas.clientWidth), height = Math.max(1, canvas.clientHeight);
    t.renderer.setPixelRatio(1);
    t.renderer.setSize(width, height, false);
    t.camera.aspect = width / height;
    t.camera.updateProjectionMatrix();
    t.renderer.render(t.scene, t.camera);
  }

  // A load finished: drawn, and the status says what is on screen.
  #ready() {
    const t = this.three;
    this.draw();
    if (!t.material) return;
    $("scene-status").textContent =
      `${t.meshName} under ${t.environmentName}; the fit ${this.fit.id.slice(0, 8)} through EXT_materials_coated_conductor. Drag to orbit, wheel to zoom.`;
    $("scene-status").classList.remove("error");
    $("scene").dataset.state = "ready";
    $("scene").dataset.fit = this.fit.id;
  }

  /** The canvas's pixels as drawn (RGBA bytes, top row first, base64: one string, not a million numbers), for the tests. */
  pixels() {
    const canvas = this.three.renderer.domElement;
    const copy = document.createElement("canvas");
    copy.width = canvas.width;
    copy.height = canvas.height;
    const context = copy.getContext("2d");
    context.drawImage(canvas, 0, 0);
    const bytes = context.getImageData(0, 0, copy.width, copy.height).data;
    let text = "";
    for (let i = 0; i < bytes.length; i += 32768) text += String.fromCharCode.apply(null, bytes.subarray(i, i + 32768));
    return { width: copy.width, height: copy.height, base64: btoa(text) };
  }
}
