// EXT_materials_coated_conductor in three.js (docs/gltf/EXT_materials_coated_conductor/):
// a MeshPhysicalMaterial whose metal Fresnel is this project's model, and
// the GLTFLoader and GLTFExporter plugins that read and write the
// extension. ES module, no build step, nothing fetched: the GLSL, the model
// kinds and the split-sum LUT are in generated/ (`python -m
// preview_shaders.three_package`); `three` is the package's peer
// dependency (an import map or a bundler resolves it). Each kind is drawn
// by its own generated cf_preview_model (generated/kinds.js, kinds.js):
// no kind is named here.
//
//   loader.register((parser) => new CoatedConductorExtension(parser));
//   const material = await createCoatedConductorMaterial({ model: extension, roughness: 0.2 });
//
// What is patched in three's MeshPhysicalMaterial shader (onBeforeCompile,
// the project's GLSL, generated/glsl.js, pasted in), so that it draws the whole
// air / coat / metal stack (docs/gltf/EXT_materials_coated_conductor/,
// "Combining with the coat"; fitting/shading/coated_layer.py is the numpy twin):
//   - direct lights: BRDF_GGX's Schlick F is the model at v.h (the cosine
//     inside the coat when there is a clear coat, Snell), through the coat
//     with the mirror's series of bounces at NdotV, per polarisation, and
//     not scaled by three's multiple-scattering compensation;
//   - image-based light: the metal's single and multiple scattering are
//     replaced by the model's directional albedo from its split-sum table
//     (albedo_table.js) through the coat: the mirror's series, and for a
//     rough metal the share of its lobe that leaves at once and the rest
//     returned over the hemisphere (escape_table.js); the coat's
//     EnvironmentBRDF by the table's coat row (the exact dielectric for a
//     smooth coat);
//   - the clear coat: its F0 from the coat's index (not 0.04); the
//     base is no longer weighted by three's 1 - clearcoat * Fcc (its
//     transmission is in the terms above).
// The coat is the material's own clear coat (three's clearcoat,
// clearcoatMap, clearcoatRoughness, clearcoatRoughnessMap, as
// KHR_materials_clearcoat loads them); its index, the draft
// KHR_materials_clearcoat_ior's clearcoatIor (default 1.5), is the model's
// coat index: the extension object carries the metal only.
// A material whose extension object fails the schema's or the range's
// rules draws its fallback (console.warn), as does every material when the
// LUT cannot be decoded.
// The model's reflectance is linear ACEScg; the stack is composed in ACEScg
// and converted to three's working space (linear Rec.709) with
// CF_ACESCG_TO_SRGB (cf_display.glsl).

import * as THREE from "three";
import { GLSL } from "./generated/glsl.js";
import { wordsFor } from "./packing.js";
import { KINDS, checkKindFields, kindNamed } from "./kinds.js";
import { AlbedoTable, lutTexture, tableSource } from "./albedo_table.js";
import { EscapeTable, ROUGH_BLEND, internalReflectance } from "./escape_table.js";

export const EXTENSION_NAME = "EXT_materials_coated_conductor";
/** The draft extension carrying the clear coat's index, nested in KHR_materials_clearcoat's object. */
export const CLEARCOAT_IOR = "KHR_materials_clearcoat_ior";
export { KINDS };

// The model's terms, pasted before three's (patched) pars chunk that calls them.
const HEAD = `
uniform sampler2D cf_albedo;
uniform sampler2D cf_escape;
uniform float cf_r_bar;
uniform float cf_rough_blend;
uniform float cf_coat_ior;
uniform uint cf_words[14];
uniform vec2 cf_eta_i_range;

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

// (R_s, R_p): the coat's reflectance from air at cosine NdotV, both
// polarisations (cf_fresnel_dielectric is their mean).
vec2 cf_coat_sp(float NdotV, float eta)
{
    float mu = cf_saturate(NdotV);
    float cos_t = sqrt(max(1.0 - (1.0 - mu * mu) / (eta * eta), 0.0));
    float rs = (mu - eta * cos_t) / max(mu + eta * cos_t, CF_FLT_MIN);
    float rp = (eta * mu - cos_t) / max(eta * mu + cos_t, CF_FLT_MIN);
    return eta <= 1.0 ? vec2(0.0) : vec2(rs * rs, rp * rp);
}

// The mirror's series: the metal's reflectance F under the coat (ACEScg, at
// the cosine in the coat) as seen from air at NdotV, per polarisation x the
// coat's transmission in and out and the series of bounces between the
// metal and the underside of the coat, (1 - R_x)^2 F / (1 - R_x F),
// averaged over s and p (fitting.optics.coated_stack, less the coat's own
// R, which the coat's lobe draws).
vec3 cf_mirror_through_coat(vec3 F, float NdotV)
{
    vec2 R = cf_coat_sp(NdotV, max(cf_coat_ior, 1.0));
    vec2 T = (1.0 - R) * (1.0 - R);
    return 0.5 * (T.x * F / max(1.0 - R.x * F, CF_FLT_MIN) + T.y * F / max(1.0 - R.y * F, CF_FLT_MIN));
}

// The metal's Fresnel under the coat at cosine c in air, ACEScg.
vec3 cf_metal_model(float c)
{
    return cf_preview_model(cf_metal_cos(c), cf_coat_ior, cf_eta_i_range, cf_words);
}

// The coat's weight (three's material.clearcoat), 0 without a coat.
#ifdef USE_CLEARCOAT
#define CF_COAT_WEIGHT(material) (material).clearcoat
#else
#define CF_COAT_WEIGHT(material) 0.0
#endif

// The metal's lobe under direct light, linear Rec.709: the model at the
// microfacet's cosine v.h carried into the coat, through the coat at NdotV.
vec3 cf_metal_fresnel(float VdotH, float NdotV, float weight)
{
    vec3 F = cf_metal_model(VdotH);
    return CF_ACESCG_TO_SRGB * mix(F, cf_mirror_through_coat(F, NdotV), weight);
}

// The metal's directional albedo (image-based light) through the coat,
// linear Rec.709 (fitting/shading/coated_layer.py): the mirror's series M,
// and for a rough metal (blend w = cf_rough_blend) the share q of its lobe
// that leaves at once and the rest returned over the hemisphere,
//   D = (1 - F_d) E [q + (1 - q) mix(X_m, X_d, w)],  S = mix(M, D, w).
vec3 cf_metal_albedo(float NdotV, float weight)
{
    float mu_t = cf_metal_cos(NdotV);
    vec3 E = cf_albedo_table_lookup(cf_albedo, 0, mu_t);
    vec3 seen = cf_mirror_through_coat(E, NdotV);
    float w = cf_rough_blend;
    if (w > 0.0)
    {
        vec3 q = cf_albedo_table_lookup(cf_escape, 0, mu_t);
        vec3 E_bar = texelFetch(cf_escape, ivec2(0, 1), 0).rgb;
        float Fd = cf_fresnel_dielectric(NdotV, max(cf_coat_ior, 1.0));
        vec3 X_mirror = (1.0 - Fd) * E / max(1.0 - Fd * E, CF_FLT_MIN);
        vec3 X_diffuse = E_bar * (1.0 - cf_r_bar) / max(1.0 - E_bar * cf_r_bar, CF_FLT_MIN);
        vec3 D = (1.0 - Fd) * E * (q + (1.0 - q) * mix(X_mirror, X_diffuse, w));
        seen = mix(seen, D, w);
    }
    return CF_ACESCG_TO_SRGB * mix(E, seen, weight);
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
    "$1vec3 F = cf_metal_fresnel( dotVH, dotNV, CF_COAT_WEIGHT( material ) );"],
  ["pars", /clearcoatSpecularIndirect \+= clearcoatRadiance \* EnvironmentBRDF\([^;]*\);/,
    "clearcoatSpecularIndirect += clearcoatRadiance * cf_coat_albedo( saturate( dot( geometryClearcoatNormal, geometryViewDir ) ) );"],
  ["pars", /vec3 indirectSpecular = radiance \* singleScattering;\s*indirectSpecular \+= multiScattering \* cosineWeightedIrradiance;/,
    "vec3 indirectSpecular = radiance * cf_metal_albedo( saturate( dot( geometryNormal, geometryViewDir ) ), CF_COAT_WEIGHT( material ) );"],
  // The model has no multiple-scattering term: direct light is not scaled by
  // three's compensation (lights_fragment_begin sets it after lights_physical_fragment).
  ["pars", /reflectedLight\.directSpecular \+= irradiance \* specularBRDF \* material\.multiScatteringCompensation;/,
    "reflectedLight.directSpecular += irradiance * specularBRDF;"],
  ["main", /#include <lights_physical_fragment>/,
    `#include <lights_physical_fragment>
    // The model has no multiple-scattering term; the coat's F0 is its index's.
    material.multiScatteringCompensation = vec3( 1.0 );
    #ifdef USE_CLEARCOAT
    material.clearcoatF0 = vec3( pow2( ( cf_coat_ior - 1.0 ) / ( cf_coat_ior + 1.0 ) ) );
    #endif`],
  // The base's transmission through the coat is in cf_metal_fresnel and cf_metal_albedo.
  ["main", /outgoingLight = outgoingLight \* \( 1\.0 - material\.clearcoat \* Fcc \)/,
    "outgoingLight = outgoingLight"],
];

function patch(text, pattern, replacement) {
  if (!pattern.test(text)) {
    throw new Error(`${EXTENSION_NAME}: three.js r${THREE.REVISION} has no ${pattern} to patch`);
  }
  return text.replace(pattern, replacement);
}

let resources = null; // Promise, made once

/**
 * The GLSL, the patched chunk, the table programs and the LUT every
 * material needs, made once (the LUT inflated at the first call).
 */
export function loadResources() {
  if (!resources) {
    resources = (async () => {
      let pars = THREE.ShaderChunk.lights_physical_pars_fragment;
      for (const [where, pattern, replacement] of PATCHES) {
        if (where === "pars") pars = patch(pars, pattern, replacement);
      }
      return { glsl: GLSL, pars, table: tableSource(), lut: await lutTexture() };
    })();
    resources.catch(() => { resources = null; }); // a failure is tried again next time
  }
  return resources;
}

const PROPERTIES = new Set(["kind", "colorSpace", "etaIRange", "degree", "coefficients", "extensions", "extras"]);

/**
 * The coat a glTF material definition composes the extension with:
 * {factor, ior}. Its KHR_materials_clearcoat's clearcoatFactor (the
 * texture, per pixel, is three's), and the index of the nested draft
 * KHR_materials_clearcoat_ior (1.5 without it); no clear coat, or a factor
 * of 0, is no coat: the metal in air, {factor: 0, ior: 1}.
 */
export function coatOf(definition) {
  const clearcoat = definition?.extensions?.KHR_materials_clearcoat;
  const factor = clearcoat && typeof clearcoat === "object" ? clearcoat.clearcoatFactor ?? 0 : 0;
  if (!(factor > 0)) return { factor: 0, ior: 1 };
  return { factor, ior: clearcoat.extensions?.[CLEARCOAT_IOR]?.clearcoatIor ?? 1.5 };
}

/**
 * The extension object `model` if it is one this module draws under a coat
 * of index `coatIor` (default 1.5, glTF's; 1: no coat); else an Error
 * naming the field and the rule: the schema's rules
 * (docs/gltf/EXT_materials_coated_conductor/schema/) and the two it cannot
 * state (lo <= hi; for a kind polynomial in the coat index, the coat's
 * index inside etaIRange); the kind's own fields by its generated entry (kinds.js).
 */
export function checkModel(model, coatIor = 1.5) {
  const fail = (what) => { throw new Error(`${EXTENSION_NAME}: ${what}`); };
  if (!model || typeof model !== "object" || Array.isArray(model)) fail("the extension must be an object");
  for (const key of Object.keys(model)) {
    if (!PROPERTIES.has(key)) fail(`\`${key}\` is not a property of the extension`);
  }
  if (!KINDS.includes(model.kind)) fail(`\`kind\` must be one of ${KINDS.join(", ")}, got ${JSON.stringify(model.kind)}`);
  if (model.colorSpace !== "ACEScg") fail(`\`colorSpace\` must be "ACEScg", got ${JSON.stringify(model.colorSpace)}`);
  const index = (x) => typeof x === "number" && x >= 1 && x <= 3;
  const range = model.etaIRange;
  if (!Array.isArray(range) || range.length !== 2 || !range.every(index) || !(range[0] <= range[1])) {
    fail(`\`etaIRange\` must be [lo, hi] with 1 <= lo <= hi <= 3, got ${JSON.stringify(range)}`);
  }
  if (!index(coatIor)) {
    fail(`the coat's index (${CLEARCOAT_IOR} \`clearcoatIor\`) must lie in [1, 3], got ${JSON.stringify(coatIor)}`);
  }
  checkKindFields(kindNamed(model.kind), { ...model, coatIor }, fail);
  return model;
}

/**
 * The hooks that make a MeshPhysicalMaterial draw `model` (an extension
 * object, checked) under its clear coat of index `coatIor` (1: no coat):
 * onBeforeCompile (the patches), onBeforeRender (the albedo table at the
 * material's roughness and clear-coat roughness) and customProgramCacheKey.
 * Set them through the material's parameters.
 */
export function coatedConductorHooks(model, resources, coatIor = 1.5) {
  checkModel(model, coatIor);
  const kind = kindNamed(model.kind);
  const words = wordsFor(kind, model.coefficients);
  const drawn = { ...model, coatIor }; // what the tables are drawn for: the metal under its coat
  const table = new AlbedoTable(resources, kind, drawn, words);
  const escape = new EscapeTable(resources.glsl, kind, drawn, words, table.nodes);
  const uniforms = {
    cf_albedo: { value: table.texture },
    cf_escape: { value: escape.texture },
    cf_r_bar: { value: internalReflectance(coatIor) },
    cf_rough_blend: { value: 0 },
    cf_coat_ior: { value: coatIor },
    cf_words: { value: words },
    cf_eta_i_range: { value: new THREE.Vector2(...(model.etaIRange || [1, 1])) },
  };
  return {
    onBeforeCompile(shader) {
      Object.assign(shader.uniforms, uniforms);
      let fragment = shader.fragmentShader.replace(
        "#include <lights_physical_pars_fragment>",
        `${resources.glsl}\n${kind.glsl}\n${HEAD}\n${resources.pars}`,
      );
      for (const [where, pattern, replacement] of PATCHES) {
        if (where === "main") fragment = patch(fragment, pattern, replacement);
      }
      shader.fragmentShader = fragment;
    },
    onBeforeRender(renderer) {
      table.draw(renderer, { roughness: this.roughness, coatRoughness: this.clearcoat > 0 ? this.clearcoatRoughness : 0 });
      uniforms.cf_rough_blend.value = Math.min(Math.max(this.roughness, 0) / ROUGH_BLEND, 1);
      if (uniforms.cf_rough_blend.value > 0) escape.draw(renderer, this.roughness);
    },
    customProgramCacheKey() {
      return `${EXTENSION_NAME}:${model.kind}`;
    },
    // userData is copied through JSON by Material.clone: the model is plain
    // JSON, and the table is reached through functions (JSON skips them):
    // dispose() frees its render target, which Material.dispose leaves.
    userData: {
      coatedConductor: {
        model, coatIor, readTable: (renderer) => table.read(renderer), readEscape: (renderer) => escape.read(renderer),
        dispose: () => { table.dispose(); escape.dispose(); },
      },
    },
  };
}

/**
 * A MeshPhysicalMaterial drawing the coated metal `params.model` (an
 * EXT_materials_coated_conductor object) under a clear coat of index
 * `params.coatIor` (default 1.5); the other params are
 * MeshPhysicalMaterial's (roughness: the metal's; clearcoat, the coat's
 * weight, default 1, and 0 for no coat: the metal in air; clearcoatRoughness
 * default 0). Resolves once the LUT is decoded (the first call only).
 */
export async function createCoatedConductorMaterial(params) {
  const { model, coatIor = 1.5, ...physical } = params;
  const resources = await loadResources();
  const coated = (physical.clearcoat ?? 1) > 0;
  const hooks = coatedConductorHooks(model, resources, coated ? coatIor : 1);
  const material = new THREE.MeshPhysicalMaterial({
    metalness: 1, color: 0xffffff, clearcoat: 1, clearcoatRoughness: 0, ...physical,
  });
  return Object.assign(material, hooks);
}
