// EXT_materials_coated_conductor with three's node materials (the package's
// `coated-conductor-three/webgpu` entry): a MeshPhysicalNodeMaterial whose
// lighting model draws the same air / coat / metal stack as the
// WebGLRenderer material (coated_conductor.js), in TSL, so that
// WebGPURenderer draws it on WebGPU and on its WebGL2 backend alike:
//   - direct lights: GGX with the model's Fresnel at v.h (the cosine in the
//     coat when there is a clear coat) through the coat, the mirror's series
//     of bounces at NdotV, per polarisation;
//   - image-based light: the model's directional albedo from the split-sum
//     table through the coat (the mirror's series; for a rough metal the
//     escape table's share of the lobe and the rest returned over the
//     hemisphere); the coat's lobe by the table's coat row;
//   - the clear coat: its F0 from the coat index, the base not weighted by
//     1 - clearcoat * Fcc (its transmission is in the terms above).
// Each kind's Fresnel is its TSL twin (node_models.js). The two tables are
// the WebGL material's own (albedo_table.js, escape_table.js, the project's
// GLSL), drawn on a small off-screen WebGL2 context of the package's and
// read into float DataTextures, which the material reads as texture nodes
// (textureLoad): redrawn when the roughness or clear-coat roughness changes.
// `three` must resolve to three's WebGL build (three.module.js) beside
// `three/webgpu` and `three/tsl`, as three's own package exports do.

import * as THREE from "three";
import { DataTexture, FloatType, MeshPhysicalNodeMaterial, NearestFilter, PhysicalLightingModel, RGBAFormat, Vector3 }
  from "three/webgpu";
import * as TSL from "three/tsl";
import { EXTENSION_NAME, checkModel, loadResources } from "./coated_conductor.js";
import { kindNamed } from "./kinds.js";
import { wordsFor } from "./packing.js";
import { AlbedoTable } from "./albedo_table.js";
import { EscapeTable, ROUGH_BLEND, internalReflectance } from "./escape_table.js";
import { nodeModelOf } from "./node_models.js";

const {
  BRDF_GGX, D_GGX, V_GGX_SmithCorrelated, clearcoat, clearcoatNormalView, clearcoatRoughness, dot, float, int, ivec2,
  max, min, mix, normalView, positionViewDirection, roughness, select, sqrt, textureLoad, uniform, vec2, vec3,
} = TSL;

const FLT_MIN = 1.17549435e-38;
// Rows of cf_display.glsl's CF_ACESCG_TO_SRGB (linear ACEScg to linear Rec.709).
const ACESCG_TO_REC709 = [
  [1.704887331, -0.624157274, -0.080886774],
  [-0.129520935, 1.138399326, -0.008779242],
  [-0.02412706, -0.124620612, 1.14882211],
];

let tableRenderer = null;

/** The package's off-screen WebGL2 renderer that draws the tables (made at first use). */
function tablesRenderer() {
  if (!tableRenderer) {
    const canvas = typeof document !== "undefined" ? document.createElement("canvas") : new OffscreenCanvas(1, 1);
    tableRenderer = new THREE.WebGLRenderer({ canvas, antialias: false, alpha: true });
  }
  return tableRenderer;
}

function floatTexture(width, height) {
  const texture = new DataTexture(new Float32Array(4 * width * height), width, height, RGBAFormat, FloatType);
  Object.assign(texture, { minFilter: NearestFilter, magFilter: NearestFilter, generateMipmaps: false });
  texture.needsUpdate = true;
  return texture;
}

/** One material's albedo and escape tables as DataTextures, redrawn on the off-screen context when asked. */
class NodeTables {
  constructor(resources, kind, model, words) {
    this.albedo = new AlbedoTable(resources, kind, model, words);
    this.escape = new EscapeTable(resources.glsl, kind, model, words, this.albedo.nodes);
    this.nodes = this.albedo.nodes;
    this.albedoTexture = floatTexture(this.nodes, 3);
    this.escapeTexture = floatTexture(this.nodes, 2);
  }

  /** Redraw for {roughness, coatRoughness} if they changed; the rough blend w. */
  update({ roughness: r, coatRoughness }) {
    const renderer = tablesRenderer();
    const read = (table, texture, rows) => {
      renderer.readRenderTargetPixels(table.target, 0, 0, this.nodes, rows, texture.image.data);
      texture.needsUpdate = true;
    };
    if (this.albedo.draw(renderer, { roughness: r, coatRoughness })) read(this.albedo, this.albedoTexture, 3);
    const blend = Math.min(Math.max(r, 0) / ROUGH_BLEND, 1);
    if (blend > 0 && this.escape.draw(renderer, r)) read(this.escape, this.escapeTexture, 2);
    return blend;
  }

  dispose() {
    this.albedo.dispose();
    this.escape.dispose();
    this.albedoTexture.dispose();
    this.escapeTexture.dispose();
  }
}

const saturate = (x) => x.clamp(0, 1);
const toRec709 = (v) => vec3(...ACESCG_TO_REC709.map((row) => dot(v, vec3(...row))));

/** cf_fresnel_dielectric: unpolarised reflectance of a dielectric of index eta from air at cosine c. */
function fresnelDielectric(c, eta) {
  const mu = saturate(c);
  const cosT = sqrt(max(float(1).sub(mu.mul(mu).oneMinus().div(eta.mul(eta))), 0));
  const rs = mu.sub(eta.mul(cosT)).div(max(mu.add(eta.mul(cosT)), FLT_MIN));
  const rp = eta.mul(mu).sub(cosT).div(max(eta.mul(mu).add(cosT), FLT_MIN));
  return select(eta.equal(1), float(0), rs.mul(rs).add(rp.mul(rp)).mul(0.5));
}

/** The coat's (R_s, R_p) from air at cosine c (0 for eta <= 1). */
function coatSP(c, eta) {
  const mu = saturate(c);
  const cosT = sqrt(max(float(1).sub(mu.mul(mu).oneMinus().div(eta.mul(eta))), 0));
  const rs = mu.sub(eta.mul(cosT)).div(max(mu.add(eta.mul(cosT)), FLT_MIN));
  const rp = eta.mul(mu).sub(cosT).div(max(eta.mul(mu).add(cosT), FLT_MIN));
  return select(eta.lessThanEqual(1), vec2(0), vec2(rs.mul(rs), rp.mul(rp)));
}

/** A row of an albedo-layout table at NdotV (cf_albedo_table_lookup: nodes at (i / (n - 1))^2). */
function lookup(texture, nodes, row, c) {
  const x = sqrt(saturate(c)).mul(nodes - 1).toVar();
  const i = int(min(x.floor(), nodes - 2)).toVar();
  const below = textureLoad(texture, ivec2(i, row)).rgb;
  const above = textureLoad(texture, ivec2(i.add(1), row)).rgb;
  return mix(below, above, x.sub(float(i)));
}

/** three's PhysicalLightingModel with the metal's Fresnel, albedo and coat of `cf` (CoatedConductorNodeMaterial). */
class CoatedConductorLightingModel extends PhysicalLightingModel {
  constructor(cf, ...flags) {
    super(...flags);
    this.cf = cf;
  }

  /** The coat's weight (0 without a coat) and the metal's cosine in the coat. */
  weight() {
    return this.clearcoat ? clearcoat : float(0);
  }

  metalCos(c) {
    if (!this.clearcoat) return saturate(c);
    const eta = max(this.cf.coatIor, 1);
    const mu = saturate(c);
    return sqrt(max(float(1).sub(mu.mul(mu).oneMinus().div(eta.mul(eta))), 0));
  }

  /** The mirror's series: F under the coat as seen from air at NdotV, averaged over s and p. */
  throughCoat(F, NdotV) {
    const R = coatSP(NdotV, max(this.cf.coatIor, 1)).toVar();
    const T = R.oneMinus().mul(R.oneMinus());
    const s = T.x.mul(F).div(max(F.mul(R.x).oneMinus(), FLT_MIN));
    const p = T.y.mul(F).div(max(F.mul(R.y).oneMinus(), FLT_MIN));
    return s.add(p).mul(0.5);
  }

  metalFresnel(VdotH, NdotV) {
    const F = this.cf.fresnel(this.metalCos(VdotH)).toVar();
    return toRec709(mix(F, this.throughCoat(F, NdotV), this.weight()));
  }

  metalAlbedo(NdotV) {
    const { albedo, escape, nodes, roughBlend: w, rBar, coatIor } = this.cf;
    const muT = this.metalCos(NdotV).toVar();
    const E = lookup(albedo, nodes, 0, muT).toVar();
    const seen = this.throughCoat(E, NdotV).toVar();
    const q = lookup(escape, nodes, 0, muT);
    const Ebar = textureLoad(escape, ivec2(0, 1)).rgb;
    const Fd = fresnelDielectric(NdotV, max(coatIor, 1)).toVar();
    const Xmirror = E.mul(Fd.oneMinus()).div(max(E.mul(Fd).oneMinus(), FLT_MIN));
    const Xdiffuse = Ebar.mul(rBar.oneMinus()).div(max(Ebar.mul(rBar).oneMinus(), FLT_MIN));
    const D = E.mul(Fd.oneMinus()).mul(q.add(q.oneMinus().mul(mix(Xmirror, Xdiffuse, w))));
    const rough = select(w.greaterThan(0), mix(seen, D, w), seen);
    return toRec709(mix(E, rough, this.weight()));
  }

  direct({ lightDirection, lightColor, reflectedLight }) {
    const dotNL = normalView.dot(lightDirection).clamp();
    const irradiance = dotNL.mul(lightColor).toVar();
    if (this.clearcoat) {
      const ccIrradiance = clearcoatNormalView.dot(lightDirection).clamp().mul(lightColor);
      const f0 = vec3(this.cf.coatF0);
      const ccBRDF = BRDF_GGX({ lightDirection, f0, f90: float(1), roughness: clearcoatRoughness,
        normalView: clearcoatNormalView });
      this.clearcoatSpecularDirect.addAssign(ccIrradiance.mul(ccBRDF));
    }
    const halfDir = lightDirection.add(positionViewDirection).normalize();
    const dotNV = normalView.dot(positionViewDirection).clamp();
    const dotNH = normalView.dot(halfDir).clamp();
    const dotVH = positionViewDirection.dot(halfDir).clamp();
    const alpha = roughness.max(0.045).pow2();
    const DV = D_GGX({ alpha, dotNH }).mul(V_GGX_SmithCorrelated({ alpha, dotNL, dotNV }));
    reflectedLight.directSpecular.addAssign(irradiance.mul(this.metalFresnel(dotVH, dotNV)).mul(DV));
  }

  indirectSpecular(builder) {
    const { radiance, reflectedLight } = builder.context;
    if (this.clearcoat) {
      const dotNVcc = clearcoatNormalView.dot(positionViewDirection).clamp();
      const coat = lookup(this.cf.albedo, this.cf.nodes, 2, dotNVcc).r;
      this.clearcoatSpecularIndirect.addAssign(this.clearcoatRadiance.mul(coat));
    }
    const dotNV = normalView.dot(positionViewDirection).clamp();
    reflectedLight.indirectSpecular.addAssign(radiance.mul(this.metalAlbedo(dotNV)));
  }

  finish({ context }) {
    const { outgoingLight } = context;
    if (this.clearcoat) {
      const coat = this.clearcoatSpecularDirect.add(this.clearcoatSpecularIndirect).mul(clearcoat);
      outgoingLight.assign(outgoingLight.add(coat));
    }
    if (this.sheen) outgoingLight.assign(outgoingLight.add(this.sheenSpecularDirect, this.sheenSpecularIndirect));
  }
}

// MeshPhysicalMaterial's properties a node material takes from a glTF-loaded one (toCoatedConductorNodeMaterial).
const COPIED = [
  "name", "side", "transparent", "opacity", "alphaMap", "alphaTest", "depthWrite", "depthTest", "color", "map",
  "roughness", "roughnessMap", "metalness", "metalnessMap", "normalMap", "normalMapType", "normalScale", "aoMap",
  "aoMapIntensity", "emissive", "emissiveMap", "emissiveIntensity", "envMap", "envMapIntensity", "clearcoat",
  "clearcoatMap", "clearcoatRoughness", "clearcoatRoughnessMap", "clearcoatNormalMap", "clearcoatNormalScale",
];

/**
 * A MeshPhysicalNodeMaterial drawing the coated metal `model` (an
 * EXT_materials_coated_conductor object, checked): made by
 * createCoatedConductorNodeMaterial or toCoatedConductorNodeMaterial,
 * which load the shared resources first.
 */
export class CoatedConductorNodeMaterial extends MeshPhysicalNodeMaterial {
  static get type() {
    return "CoatedConductorNodeMaterial";
  }

  constructor(model, resources, parameters = {}, coatIor = 1.5) {
    super();
    checkModel(model, coatIor);
    this.isCoatedConductorNodeMaterial = true;
    const kind = kindNamed(model.kind);
    const node = nodeModelOf(kind);
    const drawn = { ...model, coatIor }; // the metal under its coat (KHR_materials_clearcoat_ior's index)
    const tables = new NodeTables(resources, kind, drawn, wordsFor(kind, model.coefficients));
    const P = Object.fromEntries(Object.entries(node.parameters(drawn)).map(([p, v]) => [p, uniform(new Vector3(...v))]));
    const eta = uniform(coatIor);
    const F0 = ((coatIor - 1) / (coatIor + 1)) ** 2;
    this.cf = {
      coatIor: eta, coatF0: coatIor > 1 ? F0 : 0, nodes: tables.nodes, rBar: uniform(internalReflectance(coatIor)),
      albedo: tables.albedoTexture, escape: tables.escapeTexture,
      fresnel: (mu) => node.fresnel(TSL, mu, eta, P),
      // Redraws the tables (if the roughness changed) before each object is drawn; the rough blend.
      roughBlend: uniform(0).onObjectUpdate(() => tables.update({
        roughness: this.roughness, coatRoughness: this.clearcoat > 0 ? this.clearcoatRoughness : 0,
      })),
    };
    this.resources = resources;
    this.userData.coatedConductor = { model, coatIor, fallback: null, dispose: () => tables.dispose() };
    this.setValues({
      metalness: 1, color: 0xffffff, clearcoat: 1, clearcoatRoughness: 0, ...parameters,
    });
  }

  setupLightingModel() {
    const flags = [this.useClearcoat, this.useSheen, this.useIridescence, this.useAnisotropy, this.useTransmission,
      this.useDispersion, this.useRetroreflection, this.useDiffuseRoughness];
    return new CoatedConductorLightingModel(this.cf, ...flags);
  }

  // Each material its own program: its coefficients, coat index and tables are
  // uniforms and textures of its own node graph, which a program shared by two
  // materials (three caches programs by this key) would take from the first.
  customProgramCacheKey() {
    return `${EXTENSION_NAME}:${this.uuid}:${super.customProgramCacheKey()}`;
  }

  clone() {
    const { model, coatIor } = this.userData.coatedConductor;
    return new CoatedConductorNodeMaterial(model, this.resources, {}, coatIor).copy(this);
  }

  copy(source) {
    const { cf, userData, resources } = this;
    super.copy(source);
    Object.assign(this, { cf, resources, userData: { ...source.userData, coatedConductor: userData.coatedConductor } });
    return this;
  }

  dispose() {
    this.userData.coatedConductor.dispose();
    super.dispose();
  }
}

/**
 * A CoatedConductorNodeMaterial drawing `params.model` under a clear coat of
 * index `params.coatIor` (default 1.5), as createCoatedConductorMaterial;
 * the other params are MeshPhysicalNodeMaterial's (roughness: the metal's;
 * clearcoat, the coat's weight, default 1, and 0 for no coat: the metal in
 * air; clearcoatRoughness default 0). Resolves once the LUT is decoded (the
 * first call only).
 */
export async function createCoatedConductorNodeMaterial(params) {
  const { model, coatIor = 1.5, ...physical } = params;
  const coated = (physical.clearcoat ?? 1) > 0;
  return new CoatedConductorNodeMaterial(model, await loadResources(), physical, coated ? coatIor : 1);
}

/**
 * The node-material twin of `material` (a material the GLTFLoader plugin
 * or createCoatedConductorMaterial made, its userData.coatedConductor.model
 * the extension object): its maps, factors and coat carried over; any
 * other material is given back as it is (WebGPURenderer converts it).
 */
export async function toCoatedConductorNodeMaterial(material) {
  const model = material?.userData?.coatedConductor?.model;
  if (!model || material.isCoatedConductorNodeMaterial) return material;
  const { coatIor = 1.5 } = material.userData.coatedConductor;
  const parameters = Object.fromEntries(COPIED.filter((key) => material[key] !== undefined)
    .map((key) => [key, material[key]?.clone && !material[key].isTexture ? material[key].clone() : material[key]]));
  const twin = await createCoatedConductorNodeMaterial({ model, coatIor, ...parameters });
  twin.userData.coatedConductor.fallback = material.userData.coatedConductor.fallback ?? null;
  return twin;
}

/** Replace, in place, every coated material under `root` (a glTF scene) by its node-material twin. */
export async function useCoatedConductorNodeMaterials(root) {
  const meshes = [];
  root.traverse((object) => { if (object.isMesh) meshes.push(object); });
  for (const mesh of meshes) {
    mesh.material = Array.isArray(mesh.material)
      ? await Promise.all(mesh.material.map(toCoatedConductorNodeMaterial))
      : await toCoatedConductorNodeMaterial(mesh.material);
  }
  return root;
}
export { NODE_MODELS } from "./node_models.js";
