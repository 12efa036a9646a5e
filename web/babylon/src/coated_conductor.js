// EXT_materials_coated_conductor in Babylon.js (docs/gltf/EXT_materials_coated_conductor/):
// a MaterialPluginBase plugin for PBRMaterial whose metal reflectance under
// image-based light is this project's model, composed with Babylon's own
// clear coat (material.clearCoat) as the extension's "Combining with the
// coat" says. ES module, no build step, nothing fetched: the GLSL is in
// generated/glsl.js (`python -m preview_shaders.three_package` writes it, the
// same text as coated-conductor-three's); `@babylonjs/core` is the package's
// peer dependency (an import map or a bundler resolves it).
//
//   const plugin = new CoatedConductorPlugin(material, extension);
//
// What the plugin puts in Babylon's PBR fragment shader, before the final
// colour composition (CUSTOM_FRAGMENT_BEFORE_FINALCOLORCOMPOSITION):
//   - the metal's environment reflection: Babylon's radiance times the
//     model's reflectance E at the cosine inside the coat (Snell), seen from
//     air through the coat with the mirror's series of bounces per
//     polarisation, (1 - R_x)^2 E / (1 - R_x E) averaged over s and p, in
//     place of Babylon's F0/F90 split sum and its coat conservation factor;
//     for a rough metal E is the model times the lobe's energy from
//     Babylon's BRDF table (its split sum at F0 = F90 = 1);
//   - the clear coat's own reflection: Babylon's, with the exact dielectric
//     Fresnel of the coat index for a smooth coat (Babylon's split sum uses
//     Schlick's), its F0 from material.clearCoat.indexOfRefraction = coatIor.
// Direct (punctual) lights keep Babylon's Fresnel at the base colour.
// The model's reflectance is linear ACEScg; the stack is composed in ACEScg
// and converted to linear Rec.709 with CF_ACESCG_TO_SRGB (cf_display.glsl).

import { MaterialPluginBase } from "@babylonjs/core/Materials/materialPluginBase.js";
import { GLSL } from "./generated/glsl.js";
import { EXTENSION_NAME, checkModel } from "./check_model.js";

const UNIFORMS = ["cf_roughness", "cf_coat_roughness", "cf_coat_ior", "cf_eta_i_range", "cf_n", "cf_k", "cf_F0", "cf_a", "cf_alpha"];

// The model's terms, after the GLSL (CUSTOM_FRAGMENT_DEFINITIONS).
const HEAD = `
uniform float cf_roughness;
uniform float cf_coat_roughness;
uniform float cf_coat_ior;
uniform vec2 cf_eta_i_range;
uniform vec3 cf_n;
uniform vec3 cf_k;
uniform mat3 cf_F0;
uniform mat3 cf_a;
uniform mat3 cf_alpha;

// The cosine the metal is seen at: inside the coat when there is one.
float cf_metal_cos(float c)
{
#ifdef CLEARCOAT
    return cf_cos_in_coat(c, cf_coat_ior);
#else
    return cf_saturate(c);
#endif
}

// (R_s, R_p): the coat's reflectance from air at cosine NdotV.
vec2 cf_coat_sp(float NdotV, float eta)
{
    float mu = cf_saturate(NdotV);
    float cos_t = sqrt(max(1.0 - (1.0 - mu * mu) / (eta * eta), 0.0));
    float rs = (mu - eta * cos_t) / max(mu + eta * cos_t, CF_FLT_MIN);
    float rp = (eta * mu - cos_t) / max(eta * mu + cos_t, CF_FLT_MIN);
    return eta <= 1.0 ? vec2(0.0) : vec2(rs * rs, rp * rp);
}

// The mirror's series: E under the coat as seen from air at NdotV.
vec3 cf_mirror_through_coat(vec3 E, float NdotV)
{
    vec2 R = cf_coat_sp(NdotV, max(cf_coat_ior, 1.0));
    vec2 T = (1.0 - R) * (1.0 - R);
    return 0.5 * (T.x * E / max(1.0 - R.x * E, CF_FLT_MIN) + T.y * E / max(1.0 - R.y * E, CF_FLT_MIN));
}

// The metal's Fresnel under the coat at cosine c in air, ACEScg.
vec3 cf_metal_model(float c)
{
    float mu = cf_metal_cos(c);
#ifdef CF_NK_COEFFICIENTS
    return cf_rgb_conductor(mu, cf_coat_ior, cf_n, cf_k);
#else
    return cf_coated_conductor(mu, cf_coat_ior, cf_eta_i_range, cf_F0, cf_a, cf_alpha);
#endif
}
`;

// The stack, before Babylon adds its terms up (pbrBlockFinalColorComposition).
const COMPOSE = `
#ifdef REFLECTION
{
    float cf_NdotV = cf_saturate(NdotV);
    // The lobe's energy at the material's roughness (not Babylon's, which
    // specular anti-aliasing raises): 1 for a mirror, else Babylon's split
    // sum at F0 = F90 = 1.
    float cf_energy = cf_roughness < 1e-3 ? 1.0
        : getReflectanceFromBRDFLookup(vec3(1.0), vec3(1.0), getBRDFLookup(cf_NdotV, cf_roughness)).x;
    vec3 cf_E = cf_metal_model(cf_NdotV) * cf_energy;
#ifdef CLEARCOAT
    float cf_weight = clearcoatOut.clearCoatIntensity;
#else
    float cf_weight = 0.0;
#endif
    vec3 cf_seen = CF_ACESCG_TO_SRGB * mix(cf_E, cf_mirror_through_coat(cf_E, cf_NdotV), cf_weight);
    finalRadianceScaled = reflectionOut.environmentRadiance.rgb * cf_seen * vLightingIntensity.z;
#ifdef CLEARCOAT
    // A smooth coat's own reflection: the exact dielectric in place of Schlick's split sum.
    // (The material's coat roughness: Babylon's, raised by specular anti-aliasing, is divided out.)
    if (cf_coat_roughness < 1e-3 && cf_coat_ior > 1.0) {
        vec3 cf_brdf = getBRDFLookup(cf_NdotV, clearcoatOut.clearCoatRoughness);
        float cf_schlick = getReflectanceFromBRDFLookup(vec3(vClearCoatRefractionParams.x), cf_brdf).x;
        float cf_exact = cf_fresnel_dielectric(cf_NdotV, cf_coat_ior);
        clearcoatOut.finalClearCoatRadianceScaled *= cf_exact / max(cf_schlick, CF_FLT_MIN);
    }
#endif
}
#endif
`;

/** Whether a checked model's coefficients are a conductor's n and k (else the coated-conductor polynomials). */
function hasNK(model) {
  return Array.isArray(model.coefficients.n);
}

/** The coefficients of `rows` (per channel, per power of t) as a GLSL mat3, columns the channels. */
function mat3Of(rows) {
  const out = new Float32Array(9);
  for (let c = 0; c < 3; c++) {
    for (let j = 0; j < 3; j++) out[3 * c + j] = rows?.[c]?.[j] ?? 0;
  }
  return out;
}

/**
 * The plugin: a PBRMaterial (metallic 1) drawing `model`, an
 * EXT_materials_coated_conductor object (checked: an Error naming the
 * field for a malformed one), under a clear coat of index `coatIor`
 * (default 1.5; 1: no coat, the metal in air). The material's clear coat is
 * the coat: its index set to coatIor; its intensity and roughness (and
 * textures) are the material's with `coatFromMaterial` (as the glTF loader
 * read them from KHR_materials_clearcoat), else set to 1 and 0.
 */
export class CoatedConductorPlugin extends MaterialPluginBase {
  constructor(material, model, coatIor = 1.5, { coatFromMaterial = false } = {}) {
    const checked = checkModel(model, coatIor);
    super(material, "CoatedConductor", 200, { CF_COATED_CONDUCTOR: false, CF_NK_COEFFICIENTS: false });
    this.model = checked;
    this.coatIor = coatIor;
    this.registerForExtraEvents = true; // hardBindForSubMesh sets the uniforms at each bind
    // The kind's coefficients (checked): n and k, or F0, a and alpha over the coat index.
    const rgb = hasNK(checked);
    const C = checked.coefficients;
    this._values = {
      cf_coat_ior: coatIor,
      cf_eta_i_range: checked.etaIRange,
      cf_n: rgb ? C.n : [1, 1, 1],
      cf_k: rgb ? C.k : [0, 0, 0],
      cf_F0: mat3Of(rgb ? null : C.F0),
      cf_a: mat3Of(rgb ? null : C.a),
      cf_alpha: mat3Of(rgb ? null : C.alpha),
    };
    material.metallic = 1;
    if (!coatFromMaterial) {
      material.clearCoat.isEnabled = true;
      material.clearCoat.intensity = 1;
      material.clearCoat.roughness = 0;
    }
    material.clearCoat.indexOfRefraction = coatIor;
    // A coat of index 1 is no interface: Babylon's coat off (its Schlick
    // would still reflect at grazing), the metal seen as without a coat.
    if (coatIor <= 1) material.clearCoat.intensity = 0;
    // The coat's F0 from its index against air (not Babylon's remapping of the base's F0).
    material.clearCoat.remapF0OnInterfaceChange = false;
    this._enable(true);
  }

  getClassName() {
    return "CoatedConductorPlugin";
  }

  prepareDefines(defines) {
    defines.CF_COATED_CONDUCTOR = true;
    defines.CF_NK_COEFFICIENTS = hasNK(this.model);
  }

  getUniforms() {
    return { externalUniforms: UNIFORMS };
  }

  hardBindForSubMesh(_uniformBuffer, _scene, _engine, subMesh) {
    const effect = subMesh.effect;
    if (!effect) return;
    const v = this._values;
    effect.setFloat("cf_roughness", this._material.roughness ?? 1);
    effect.setFloat("cf_coat_roughness", this._material.clearCoat.roughness);
    effect.setFloat("cf_coat_ior", v.cf_coat_ior);
    effect.setFloat2("cf_eta_i_range", ...v.cf_eta_i_range);
    effect.setFloat3("cf_n", ...v.cf_n);
    effect.setFloat3("cf_k", ...v.cf_k);
    effect.setMatrix3x3("cf_F0", v.cf_F0);
    effect.setMatrix3x3("cf_a", v.cf_a);
    effect.setMatrix3x3("cf_alpha", v.cf_alpha);
  }

  getCustomCode(shaderType) {
    if (shaderType !== "fragment") return null;
    return {
      CUSTOM_FRAGMENT_DEFINITIONS: `${GLSL}\n${HEAD}`,
      CUSTOM_FRAGMENT_BEFORE_FINALCOLORCOMPOSITION: COMPOSE,
    };
  }
}

export { EXTENSION_NAME, checkModel };
