// coated-conductor-three: EXT_materials_coated_conductor in three.js.
// The material (coated_conductor.js), the GLTFLoader plugin
// (gltf_loader.js) and the GLTFExporter plugin (gltf_exporter.js); the
// GLSL, the model kinds and the split-sum LUT are inside (generated/,
// from the project's registry and GLSL), nothing is fetched.

export {
  CLEARCOAT_IOR, EXTENSION_NAME, KINDS, checkModel, coatOf, coatedConductorHooks, createCoatedConductorMaterial,
  loadResources,
} from "./coated_conductor.js";
export { MODEL_KINDS } from "./kinds.js";
export { CoatedConductorExtension } from "./gltf_loader.js";
export { CoatedConductorExporterExtension } from "./gltf_exporter.js";
