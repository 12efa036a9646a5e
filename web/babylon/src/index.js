// coated-conductor-babylon: EXT_materials_coated_conductor in Babylon.js.
// The PBRMaterial plugin (coated_conductor.js) and the glTF loader
// extension (gltf_loader.js); the GLSL is inside (generated/), nothing is fetched.

export { CoatedConductorPlugin } from "./coated_conductor.js";
export { CLEARCOAT_IOR, EXTENSION_NAME, KINDS, checkModel, coatOf } from "./check_model.js";
export {
  CoatedConductorLoaderExtension, registerCoatedConductorExtension, unregisterCoatedConductorExtension,
} from "./gltf_loader.js";
