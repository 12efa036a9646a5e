// EXT_materials_coated_conductor in three.js (docs/gltf/EXT_materials_coated_conductor/):
// a MeshPhysicalMaterial whose metal Fresnel is this project's model, and
// the GLTFLoader plugin that makes one from a glTF material with the
// extension. ES module, no build step; `three` comes from the page's
// import map.
//
//   loader.register((parser) => new CoatedConductorExtension(parser));
//   const material = await createCoatedConductorMaterial({ model: extension, roughness: 0.2 });
//
// What is patched in three's MeshPhysicalMaterial shader (onBeforeCompile,
// the project's GLSL from /glsl/ pasted in):
//   - direct lights: BRDF_GGX's Schlick F is the model at v.h (the
//     cosine inside the coat when there is a clear coat, Snell);
//   - image-based light: the metal's single and multiple scattering are
//     replaced by the model's directional albedo from its split-sum table
//     (albedo_table.js), the coat's EnvironmentBRDF by the table's coat row;
//   - the clear coat: its F0 from the coat index coatIor (not 0.04), and
//     the base seen through it weighted by (1 - F_c(NdotV))^2, the exact
//     dielectric in and out, as the project's coated split sum
//     (cf_ibl_coated.glsl) instead of three's (1 - Schlick).
// The model's reflectance is linear ACEScg; it is converted to three's
// working space (linear Rec.709) with CF_ACESCG_TO_SRGB (cf_display.glsl).

import * as THREE from "three";
import { loadIncludes } from "../glsl.js";
import { packedWords } from "../kinds.js";
import { AlbedoTable, lutTexture, tableSources } from "./albedo_table.js";

export const EXTENSION_NAME = "EXT_materials_coated_conductor";
export const KINDS = ["coated-conductor", "rgb-conductor"];
export const DEFAULT_OPTIONS = { glslBase: "/glsl", lutUrl: "/api/v1/ibl-lut" };

const INCLUDES = [
  "cf_coated_conductor.glsl", "cf_rgb_conductor.glsl", "cf_ibl_coated.glsl",
  "cf_reference_albedo.glsl", "cf_display.glsl",
];

// The model's terms, pasted before three's (patched) pars chunk that calls them.
const HEAD = `
uniform sampler2D cf_albedo;
uniform float cf_coat_ior;
uniform uint cf_words[14];
uniform vec2 cf_eta_i_range;
uniform vec3 cf_n;
uniform vec3 cf_k;

// The cosine the metal is seen at: inside the coat when there is one
// (three's USE_CLEARCOAT), else the camera is in the coat's medium.
float cf_metal_cos(float c)
{
#ifdef USE_CLEARCOAT
    return cf_cos_in_coat(c, cf_coat_ior);
#else
    return cf_saturate(c);
#endif
}

// The metal's Fresnel at cosine c (direct lights), linear Rec.709.
vec3 cf_metal_fresnel(float c)
{
    float mu = cf_metal_cos(c);
#if CF_RGB_CONDUCTOR
    vec3 F = cf_rgb_conductor(mu, cf_coat_ior, cf_n, cf_k);
#else
    vec3 F = cf_coated_conductor_packed(mu, cf_coat_ior, cf_eta_i_range, cf_words);
#endif
    return CF_ACESCG_TO_SRGB * F;
}

// The metal's directional albedo (image-based light), linear Rec.709.
vec3 cf_metal_albedo(float NdotV)
{
    return CF_ACESCG_TO_SRGB * cf_albedo_table_lookup(cf_albedo, 0, cf_metal_cos(NdotV));
}

// The coat's own directional albedo, grey.
float cf_coat_albedo(float NdotV)
{
    return cf_albedo_table_lookup(cf_albedo, 2, NdotV).r;
}
`;

// [chunk, pattern, replacement]: each must match once, or the three.js
// release differs from the one this was written for (scripts/three).
const PATCHES = [
  ["pars", /(vec3 BRDF_GGX\( const in vec3 lightDir[\s\S]*?)vec3 F = F_Schlick\( f0, f90, dotVH \);/,
    "$1vec3 F = cf_metal_fresnel( dotVH );"],
  ["pars", /clearcoatSpecularIndirect \+= clearcoatRadiance \* EnvironmentBRDF\([^;]*\);/,
    "clearcoatSpecularIndirect += clearcoatRadiance * cf_coat_albedo( saturate( dot( geometryClearcoatNormal, geometryViewDir ) ) );"],
  ["pars", /vec3 indirectSpecular = radiance \* singleScattering;\s*indirectSpecular \+= multiScattering \* cosineWeightedIrradiance;/,
    "vec3 indirectSpecular = radiance * cf_metal_albedo( saturate( dot( geometryNormal, geometryViewDir ) ) );"],
  ["main", /#include <lights_physical_fragment>/,
    `#include <lights_physical_fragment>
    // The model has no multiple-scattering term; the coat's F0 is its index's.
    material.multiScatteringCompensation = vec3( 1.0 );
    #ifdef USE_CLEARCOAT
    material.clearcoatF0 = vec3( pow2( ( cf_coat_ior - 1.0 ) / ( cf_coat_ior + 1.0 ) ) );
    #endif`],
  ["main", /outgoingLight = outgoingLight \* \( 1\.0 - material\.clearcoat \* Fcc \)/,
    "outgoingLight = outgoingLight * mix( 1.0, cf_coat_transmission( dotNVcc, cf_coat_ior ), material.clearcoat )"],
];

function patch(text, pattern, replacement) {
  if (!pattern.test(text)) {
    throw new Error(`${EXTENSION_NAME}: three.js r${THREE.REVISION} has no ${pattern} to patch`);
  }
  return text.replace(pattern, replacement);
}

const resourcesFor = new Map(); // JSON of options -> Promise

/** The GLSL and the LUT every material needs, fetched once per set of options. */
export function loadResources(options = {}) {
  const { glslBase, lutUrl } = { ...DEFAULT_OPTIONS, ...options };
  const key = JSON.stringify([glslBase, lutUrl]);
  if (!resourcesFor.has(key)) {
    resourcesFor.set(key, (async () => {
      const [glsl, tables, lut] = await Promise.all([
        loadIncludes(INCLUDES, glslBase),
        tableSources(glslBase),
        fetch(lutUrl).then((r) => {
          if (!r.ok) throw new Error(`${EXTENSION_NAME}: the LUT ${lutUrl}: ${r.status} ${r.statusText}`);
          return r.arrayBuffer();
        }),
      ]);
      let pars = THREE.ShaderChunk.lights_physical_pars_fragment;
      for (const [where, pattern, replacement] of PATCHES) {
        if (where === "pars") pars = patch(pars, pattern, replacement);
      }
      return { glsl, pars, tables, lut: lutTexture(lut) };
    })());
  }
  return resourcesFor.get(key);
}

/**
 * The extension object `model` if it is one this module draws; else an
 * Error naming the field and the rule (the schema's rules that matter to
 * the shader).
 */
export function checkModel(model) {
  const fail = (what) => { throw new Error(`${EXTENSION_NAME}: ${what}`); };
  if (!model || typeof model !== "object") fail("the extension must be an object");
  if (!KINDS.includes(model.kind)) fail(`\`kind\` must be one of ${KINDS.join(", ")}, got ${JSON.stringify(model.kind)}`);
  if (model.colorSpace !== "ACEScg") fail(`\`colorSpace\` must be "ACEScg", got ${JSON.stringify(model.colorSpace)}`);
  const eta = model.coatIor;
  if (!(eta >= 1 && eta <= 3)) fail(`\`coatIor\` must lie in [1, 3], got ${eta}`);
  const C = model.coefficients || {};
  const numbers = (row, n) => Array.isArray(row) && row.length === n && row.every(Number.isFinite);
  if (model.kind === "rgb-conductor") {
    if (!numbers(C.n, 3) || !numbers(C.k, 3)) fail("`coefficients` of an rgb-conductor must be n and k, three numbers each");
  } else {
    const [lo, hi] = model.etaIRange || [];
    if (!(lo <= hi)) fail(`\`etaIRange\` must be [lo, hi] with lo <= hi, got ${JSON.stringify(model.etaIRange)}`);
    const d = model.degree;
    if (![0, 1, 2].includes(d)) fail(`\`degree\` must be 0, 1 or 2, got ${d}`);
    for (const p of ["F0", "a", "alpha"]) {
      if (!Array.isArray(C[p]) || C[p].length !== 3 || !C[p].every((row) => numbers(row, d + 1))) {
        fail(`\`coefficients.${p}\` must be three rows of ${d + 1} numbers`);
      }
    }
  }
  return model;
}

/**
 * The hooks that make a MeshPhysicalMaterial draw `model` (an extension
 * object, checked): onBeforeCompile (the patches), onBeforeRender (the
 * albedo table at the material's roughness and clear-coat roughness) and
 * customProgramCacheKey. Set them through the material's parameters.
 */
export function coatedConductorHooks(model, resources) {
  checkModel(model);
  const rgb = model.kind === "rgb-conductor";
  const words = rgb ? new Uint32Array(14) : packedWords(model.coefficients);
  const table = new AlbedoTable(resources, model, words);
  const uniforms = {
    cf_albedo: { value: table.texture },
    cf_coat_ior: { value: model.coatIor },
    cf_words: { value: words },
    cf_eta_i_range: { value: new THREE.Vector2(...(model.etaIRange || [1, 1])) },
    cf_n: { value: new THREE.Vector3(...(rgb ? model.coefficients.n : [1, 1, 1])) },
    cf_k: { value: new THREE.Vector3(...(rgb ? model.coefficients.k : [0, 0, 0])) },
  };
  return {
    onBeforeCompile(shader) {
      Object.assign(shader.uniforms, uniforms);
      let fragment = shader.fragmentShader.replace(
        "#include <lights_physical_pars_fragment>",
        `#define CF_RGB_CONDUCTOR ${rgb ? 1 : 0}\n${resources.glsl}\n${HEAD}\n${resources.pars}`,
      );
      for (const [where, pattern, replacement] of PATCHES) {
        if (where === "main") fragment = patch(fragment, pattern, replacement);
      }
      shader.fragmentShader = fragment;
    },
    onBeforeRender(renderer) {
      table.draw(renderer, { roughness: this.roughness, coatRoughness: this.clearcoat > 0 ? this.clearcoatRoughness : 0 });
    },
    customProgramCacheKey() {
      return `${EXTENSION_NAME}:${model.kind}`;
    },
    // userData is copied through JSON by Material.clone: the model is plain
    // JSON, and the table is reached through functions (JSON skips them):
    // dispose() frees its render target, which Material.dispose leaves.
    userData: {
      coatedConductor: { model, readTable: (renderer) => table.read(renderer), dispose: () => table.dispose() },
    },
  };
}

/**
 * A MeshPhysicalMaterial drawing the coated metal `params.model` (an
 * EXT_materials_coated_conductor object); the other params are
 * MeshPhysicalMaterial's (roughness: the metal's; clearcoat default 1,
 * clearcoatRoughness default model.coatRoughnessFactor). `options`:
 * {glslBase, lutUrl}, where the project's GLSL and split-sum LUT are
 * served. Resolves once the GLSL and the LUT are in.
 */
export async function createCoatedConductorMaterial(params, options = {}) {
  const { model, ...physical } = params;
  const resources = await loadResources(options);
  const hooks = coatedConductorHooks(model, resources);
  const material = new THREE.MeshPhysicalMaterial({
    metalness: 1, color: 0xffffff, clearcoat: 1, clearcoatRoughness: model.coatRoughnessFactor ?? 0,
    ...physical,
  });
  return Object.assign(material, hooks);
}

/**
 * The GLTFLoader plugin: a material with EXT_materials_coated_conductor
 * becomes a MeshPhysicalMaterial drawing the model (its other properties,
 * read by the loader as usual); without the extension nothing changes. The
 * coat is the extension's (coatFactor, default 1, and coatRoughnessFactor),
 * not KHR_materials_clearcoat's factor, which is the fallback's.
 */
export class CoatedConductorExtension {
  constructor(parser, options = {}) {
    this.parser = parser;
    this.name = EXTENSION_NAME;
    this.options = options;
  }

  #extension(materialIndex) {
    const def = this.parser.json.materials?.[materialIndex];
    return def?.extensions?.[this.name] ?? null;
  }

  getMaterialType(materialIndex) {
    return this.#extension(materialIndex) ? THREE.MeshPhysicalMaterial : null;
  }

  async extendMaterialParams(materialIndex, materialParams) {
    const model = this.#extension(materialIndex);
    if (!model) return;
    const resources = await loadResources(this.options);
    Object.assign(materialParams, { clearcoat: model.coatFactor ?? 1,
                                    clearcoatRoughness: model.coatRoughnessFactor ?? 0 });
    Object.assign(materialParams, { metalness: 1 }, coatedConductorHooks(model, resources));
  }

  /**
   * The loader puts clones of a material on meshes (assignFinalMaterial:
   * derivative tangents, vertex colours, flat shading), and a clone keeps
   * neither the hooks nor the table: each gets its own here.
   */
  async afterRoot(result) {
    const resources = await loadResources(this.options);
    for (const scene of result.scenes ?? [result.scene]) {
      scene.traverse((object) => {
        for (const material of [object.material ?? []].flat()) {
          const index = this.parser.associations.get(material)?.materials;
          const model = index === undefined ? null : this.#extension(index);
          if (!model || material.userData.coatedConductor?.readTable) continue;
          const { userData, ...hooks } = coatedConductorHooks(model, resources);
          Object.assign(material, hooks);
          Object.assign(material.userData, userData);
        }
      });
    }
  }
}
