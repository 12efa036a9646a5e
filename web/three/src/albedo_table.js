// The split-sum albedo table of a coated-metal material in three.js: the
// project's own albedo_table.frag (the model's split sum from the LUT for a
// kind with the lookup, generated/kinds.js splitSum), drawn by three into an
// n x 3 float target: row 0 the metal's lobe, row 2 the coat's, at NdotV =
// (i / (n - 1))^2 (cf_albedo_table_lookup reads it). For a kind without the
// lookup, row 0 is drawn over by the kind's modelTable (model_albedo_table.frag
// with its generated cf_preview_model: the GGX lobe of its Fresnel by
// quadrature). The same tables, from the same GLSL and LUT, as the editor's
// preview (static/splitsum.js), so the two agree to float rounding. Both come
// with the package (generated/, `python -m preview_shaders.three_package`):
// nothing is fetched.

import * as THREE from "three";
import { lutTexels } from "./lut.js";
import { TABLE_SOURCES } from "./generated/glsl.js";

// Quadrature points per node of the model row of a kind without the
// split-sum lookup: the editor's REFERENCE_SAMPLES (static/splitsum.js), the
// preview's reference albedo.
export const MODEL_SAMPLES = 2048;

const VERTEX = `in vec3 position;
void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }`;

/** The LUT as an RGBA float 3D texture ({texture, width, alphaRange}). */
export async function lutTexture() {
  const lut = await lutTexels();
  const texels = lut.width * lut.height * lut.depth;
  const rgba = new Float32Array(4 * texels);
  for (let i = 0; i < texels; i++) {
    rgba.set(lut.data.subarray(3 * i, 3 * i + 3), 4 * i);
    rgba[4 * i + 3] = 1;
  }
  const texture = new THREE.Data3DTexture(rgba, lut.width, lut.height, lut.depth);
  Object.assign(texture, {
    format: THREE.RGBAFormat, type: THREE.FloatType, minFilter: THREE.NearestFilter,
    magFilter: THREE.NearestFilter, generateMipmaps: false, unpackAlignment: 4, needsUpdate: true,
  });
  return { texture, width: lut.width, alphaRange: lut.alphaRange };
}

/** The split-sum table program (GLSL ES 3.00 without the #version line, which three writes). */
export function tableSource() {
  return TABLE_SOURCES["albedo_table.frag"];
}

/** A pass of `fragmentShader` over rows [0, rows) of a 3-row target (3: the whole), drawn in `order`. */
function pass(fragmentShader, uniforms, rows, order) {
  const material = new THREE.RawShaderMaterial({
    glslVersion: THREE.GLSL3, vertexShader: VERTEX, fragmentShader, uniforms, depthTest: false, depthWrite: false,
  });
  const height = (2 * rows) / 3;
  const mesh = new THREE.Mesh(new THREE.PlaneGeometry(2, height).translate(0, -1 + height / 2, 0), material);
  mesh.frustumCulled = false;
  mesh.renderOrder = order;
  return mesh;
}

/**
 * One material's table: `draw(renderer, settings)` renders it for
 * {roughness, coatRoughness} when they (or the model) changed since the
 * last time; `texture` is the table.
 */
/**
 * Render `scene` through `camera` into `target` without clearing it, then
 * give the renderer back its render target and autoClear (the tables'
 * off-screen passes: AlbedoTable, EscapeTable).
 */
export function drawInto(renderer, target, scene, camera) {
  const previous = renderer.getRenderTarget();
  const autoClear = renderer.autoClear;
  renderer.autoClear = false;
  renderer.setRenderTarget(target);
  renderer.render(scene, camera);
  renderer.setRenderTarget(previous);
  renderer.autoClear = autoClear;
}

export class AlbedoTable {
  /** `kind`: the model's generated entry (kinds.js); `words`: its coefficients packed. */
  constructor(resources, kind, model, words) {
    this.model = model;
    this.nodes = 2 * (resources.lut.width - 1) + 1;
    this.target = new THREE.WebGLRenderTarget(this.nodes, 3, {
      type: THREE.FloatType, format: THREE.RGBAFormat, minFilter: THREE.NearestFilter,
      magFilter: THREE.NearestFilter, depthBuffer: false, generateMipmaps: false,
    });
    this.texture = this.target.texture;
    const uniforms = {
      u_resolution: { value: new THREE.Vector2(this.nodes, 3) },
      u_eta_i: { value: model.coatIor },
      u_roughness: { value: 0 },
      u_coat_roughness: { value: 0 },
      cf_lut: { value: resources.lut.texture },
      cf_alpha_range: { value: new THREE.Vector2(...resources.lut.alphaRange) },
      cf_words: { value: words },
      cf_eta_i_range: { value: new THREE.Vector2(...model.etaIRange) },
      // The Lazanyi row is not read here; its inputs stay 0.
      cf_F0_air: { value: new THREE.Vector3() },
      cf_F82_air: { value: new THREE.Vector3() },
      u_samples: { value: MODEL_SAMPLES },
    };
    this.uniforms = uniforms;
    this.scene = new THREE.Scene();
    // The split-sum rows (the coat's among them), then the model's own row 0 for a kind without the lookup.
    this.scene.add(pass(resources.table, uniforms, 3, 0));
    if (!kind.splitSum) this.scene.add(pass(kind.modelTable, uniforms, 1, 1));
    this.camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
    this.drawnFor = null;
  }

  /** Render the table if {roughness, coatRoughness} differ from the last drawn. */
  draw(renderer, { roughness, coatRoughness }) {
    const key = `${roughness} ${coatRoughness}`;
    if (key === this.drawnFor) return false;
    this.uniforms.u_roughness.value = roughness;
    this.uniforms.u_coat_roughness.value = coatRoughness;
    drawInto(renderer, this.target, this.scene, this.camera);
    this.drawnFor = key;
    return true;
  }

  /** The table as drawn ({nodes, data: nodes x 3 RGBA floats, row 0 first}), for the tests. */
  read(renderer) {
    const data = new Float32Array(4 * this.nodes * 3);
    renderer.readRenderTargetPixels(this.target, 0, 0, this.nodes, 3, data);
    return { nodes: this.nodes, data: Array.from(data) };
  }

  dispose() {
    this.target.dispose();
    for (const mesh of this.scene.children) {
      mesh.geometry.dispose();
      mesh.material.dispose();
    }
  }
}
