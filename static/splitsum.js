// The split sum of the preview's rough lobes (Karis 2013): the service's
// pre-integrated LUT (GET /api/v1/ibl-lut) and prefiltered environments
// (GET /api/v1/environments/{name}/prefiltered), fetched once each on first
// use; the split-sum variant of shader_ball.frag; and its albedo tables
// over NdotV, which albedo_table.frag (model, Lazanyi, coat, from the LUT)
// and reference_albedo.frag (the reference, from its texture) integrate
// when the fit, eta_i or a roughness change, never per frame. For a kind
// without the split-sum lookup (kinds.js: splitSum false) the model's row
// is the GGX lobe of the kind's own Fresnel by quadrature
// (model_albedo_table.frag with the kind's cf_preview_model.glsl), drawn
// over albedo_table.frag's row 0.

import * as api from "./api.js";
import { drawInto, floatTarget, fullscreenProgram, readTarget } from "./glpass.js";

// The reference's albedo with 2048 Hammersley points a node
// (preview_shaders.rough.reference_albedo_table's).
export const REFERENCE_SAMPLES = 2048;
export const ENVIRONMENT_NAMES = ["white_sky", "studio", "outdoor"];
// Texture units, each sampler type on its own (WebGL2 refuses a draw whose
// samplers of two types share a unit).
export const UNIT = { reference: 0, albedo: 1, referenceAlbedo: 2, prefiltered: 3, lut: 4 };

/**
 * The uniforms every program of the preview shares: the fit (packed
 * halves, domain), the Lazanyi inputs, the reference's range, eta_i and the
 * lobes. A uniform a program lacks is skipped (its location is null).
 */
export function setMaterial(gl, u, s) {
  gl.uniform1f(u.u_eta_i, s.eta);
  gl.uniform1uiv(u.cf_words, s.words);
  gl.uniform2f(u.cf_eta_i_range, ...s.etaRange);
  gl.uniform3f(u.cf_F0_air, ...s.F0);
  gl.uniform3f(u.cf_F82_air, ...s.F82);
  gl.uniform2f(u.u_reference_eta_i_range, ...s.referenceRange);
  gl.uniform1f(u.u_roughness, s.roughness);
  gl.uniform1i(u.u_coated, s.coated ? 1 : 0);
  gl.uniform1f(u.u_coat_roughness, s.coatRoughness);
}

function texture3D(gl, target, format, data, width, height, depth, filter) {
  const texture = gl.createTexture();
  gl.bindTexture(target, texture);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
  gl.texImage3D(target, 0, format, width, height, depth, 0, gl.RGB, gl.FLOAT, data);
  for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(target, p, filter);
  // Equirect slices wrap around in azimuth; everything else clamps.
  gl.texParameteri(target, gl.TEXTURE_WRAP_S, target === gl.TEXTURE_2D_ARRAY ? gl.REPEAT : gl.CLAMP_TO_EDGE);
  for (const p of [gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(target, p, gl.CLAMP_TO_EDGE);
  return texture;
}

export class SplitSum {
  constructor(gl, vao) {
    this.gl = gl;
    this.vao = vao;
    this.loads = new Map(); // what -> Promise
    this.programs = new Map(); // model kind's name -> shader_ball.frag with CF_SPLIT_SUM 1
    this.tablePass = null;
    this.modelTablePasses = new Map(); // model kind's name -> model_albedo_table.frag (kinds without the lookup)
    this.referencePass = null;
    this.lut = null;
    this.alphaRange = null;
    this.prefiltered = new Map(); // environment index -> 2D array texture
    // The tables' NdotV nodes (i / (n - 1))^2, n - 1 twice the LUT's: its
    // nodes are among them, so the model's table reproduces its lookup.
    this.nodes = 0;
    this.albedo = null; // nodes x 3: model, Lazanyi, coat
    this.referenceAlbedo = null; // nodes x 1
    this.albedoFor = null;
    this.referenceAlbedoFor = null;
  }

  #once(what, make) {
    if (!this.loads.has(what)) this.loads.set(what, make());
    return this.loads.get(what);
  }

  /** The split-sum program of model kind `kind` (kinds.js; undefined until loaded). */
  programFor(kind) {
    return this.programs.get(kind.name);
  }

  /**
   * A promise of the programs of model kind `kind` (kinds.js), the LUT and
   * the slices of `environment` (an index).
   */
  load(environment, kind) {
    const gl = this.gl;
    const programs = this.#once("programs", async () => {
      const [tablePass, referencePass] = await Promise.all([
        fullscreenProgram(gl, "albedo_table.frag"),
        fullscreenProgram(gl, "reference_albedo.frag"),
      ]);
      Object.assign(this, { tablePass, referencePass });
    });
    const program = this.#once(`program ${kind.name}`, async () => {
      const [made, modelTablePass] = await Promise.all([
        fullscreenProgram(gl, "shader_ball.frag", { CF_SPLIT_SUM: 1 }, kind.sources),
        kind.splitSum ? null : fullscreenProgram(gl, "model_albedo_table.frag", {}, kind.sources),
      ]);
      if (modelTablePass) this.modelTablePasses.set(kind.name, modelTablePass);
      this.programs.set(kind.name, made);
    });
    const lut = this.#once("lut", async () => {
      const table = await api.iblLut();
      this.lut = texture3D(gl, gl.TEXTURE_3D, gl.RGB32F, table.data, table.width, table.height, table.depth, gl.NEAREST);
      this.alphaRange = table.alphaRange;
      this.nodes = 2 * (table.width - 1) + 1;
      this.albedo = floatTarget(gl, this.nodes, 3);
      this.referenceAlbedo = floatTarget(gl, this.nodes, 1);
    });
    const name = ENVIRONMENT_NAMES[environment];
    const slices = this.#once(name, async () => {
      const env = await api.prefilteredEnvironment(name);
      // Filtering float32 needs OES_texture_float_linear; half floats
      // (1e-3 relative) filter everywhere.
      const format = gl.getExtension("OES_texture_float_linear") ? gl.RGB32F : gl.RGB16F;
      this.prefiltered.set(environment, texture3D(
        gl, gl.TEXTURE_2D_ARRAY, format, env.data, env.width, env.height, env.layers, gl.LINEAR,
      ));
    });
    return Promise.all([programs, program, lut, slices]).then(() => undefined);
  }

  /** Whether load(environment, kind) has completed. */
  loaded(environment, kind) {
    return this.tablePass !== null && this.programs.has(kind.name) && this.lut !== null && this.prefiltered.has(environment);
  }

  /**
   * Integrate the albedo tables of state `s` where its fit, eta_i or
   * roughness changed since the last time (the reference only when its
   * band is shown); `reference` is the reference texture.
   */
  integrate(s, reference, withReference) {
    const gl = this.gl;
    const key = JSON.stringify([s.kind.name, Array.from(s.words), s.etaRange, s.F0, s.F82, s.eta, s.roughness, s.coatRoughness]);
    if (key !== this.albedoFor) {
      const u = this.tablePass.uniforms;
      gl.useProgram(this.tablePass.program);
      gl.uniform2f(u.u_resolution, this.nodes, 3);
      setMaterial(gl, u, s);
      gl.uniform2f(u.cf_alpha_range, ...this.alphaRange);
      gl.activeTexture(gl.TEXTURE0 + UNIT.lut);
      gl.bindTexture(gl.TEXTURE_3D, this.lut);
      gl.uniform1i(u.cf_lut, UNIT.lut);
      drawInto(gl, this.vao, [this.albedo], this.nodes, 3);
      if (!s.kind.splitSum) this.#modelRow(s);
      this.albedoFor = key;
    }
    const referenceKey = JSON.stringify([s.referenceFor, s.referenceRange, s.eta, s.roughness]);
    if (withReference && referenceKey !== this.referenceAlbedoFor) {
      const u = this.referencePass.uniforms;
      gl.useProgram(this.referencePass.program);
      gl.uniform2f(u.u_resolution, this.nodes, 1);
      setMaterial(gl, u, s);
      gl.uniform1i(u.u_samples, REFERENCE_SAMPLES);
      gl.activeTexture(gl.TEXTURE0 + UNIT.reference);
      gl.bindTexture(gl.TEXTURE_2D, reference);
      gl.uniform1i(u.u_reference, UNIT.reference);
      drawInto(gl, this.vao, [this.referenceAlbedo], this.nodes, 1);
      this.referenceAlbedoFor = referenceKey;
    }
  }

  // The model row (row 0) of a kind without the split-sum lookup, from
  // model_albedo_table.frag, over albedo_table.frag's (rows 1 and 2,
  // Lazanyi and the coat, are kept: the scissor lets the pass write row 0 only).
  #modelRow(s) {
    const pass = this.modelTablePasses.get(s.kind.name);
    const gl = this.gl, u = pass.uniforms;
    gl.useProgram(pass.program);
    gl.uniform2f(u.u_resolution, this.nodes, 3);
    setMaterial(gl, u, s);
    gl.uniform1i(u.u_samples, REFERENCE_SAMPLES);
    gl.enable(gl.SCISSOR_TEST);
    gl.scissor(0, 0, this.nodes, 1);
    drawInto(gl, this.vao, [this.albedo], this.nodes, 3);
    gl.disable(gl.SCISSOR_TEST);
  }

  /** Bind the split-sum program's tables and slices (its program in use). */
  bind(u, environment) {
    const gl = this.gl;
    const textures = [
      [UNIT.albedo, gl.TEXTURE_2D, this.albedo, u.u_albedo],
      [UNIT.referenceAlbedo, gl.TEXTURE_2D, this.referenceAlbedo, u.u_reference_albedo],
      [UNIT.prefiltered, gl.TEXTURE_2D_ARRAY, this.prefiltered.get(environment), u.u_prefiltered],
    ];
    for (const [unit, target, texture, location] of textures) {
      gl.activeTexture(gl.TEXTURE0 + unit);
      gl.bindTexture(target, texture);
      gl.uniform1i(location, unit);
    }
  }

  /** The albedo tables as integrated last ({nodes, albedo: 3 rows, reference: 1 row}, RGBA floats), for the parity tests. */
  readTables() {
    return {
      nodes: this.nodes,
      albedo: Array.from(readTarget(this.gl, this.albedo, this.nodes, 3)),
      reference: Array.from(readTarget(this.gl, this.referenceAlbedo, this.nodes, 1)),
    };
  }
}
