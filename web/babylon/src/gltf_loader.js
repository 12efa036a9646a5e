// The Babylon.js glTF loader extension of EXT_materials_coated_conductor: a
// material with the extension gets the CoatedConductorPlugin
// (coated_conductor.js) after the loader has read its other properties
// (KHR_materials_clearcoat's included: the coat the metal lies under, its
// factor, roughness and textures Babylon's, its index the nested draft
// KHR_materials_clearcoat_ior's, 1.5 without it); a malformed or out-of-range
// extension object draws the fallback with a console warning, never an exception.
//
//   import { registerCoatedConductorExtension } from "coated-conductor-babylon";
//   registerCoatedConductorExtension();  // before loading

import { GLTFLoader } from "@babylonjs/loaders/glTF/2.0/glTFLoader.js";
import { registerGLTFExtension, unregisterGLTFExtension } from "@babylonjs/loaders/glTF/2.0/glTFLoaderExtensionRegistry.js";
import { CoatedConductorPlugin } from "./coated_conductor.js";
import { EXTENSION_NAME, checkModel, coatOf } from "./check_model.js";

/** The IGLTFLoaderExtension: one per loader. */
export class CoatedConductorLoaderExtension {
  constructor(loader) {
    this.name = EXTENSION_NAME;
    this.enabled = true;
    this._loader = loader;
  }

  dispose() {
    this._loader = null;
  }

  loadMaterialPropertiesAsync(context, material, babylonMaterial) {
    const object = material.extensions?.[EXTENSION_NAME];
    if (object === undefined) return null;
    let model;
    const coatIor = coatOf(material).ior;
    try {
      model = checkModel(object, coatIor);
    } catch (error) {
      console.warn(`${error.message}; material ${material.index} (${material.name ?? "unnamed"}) draws its fallback`);
      return null;
    }
    return GLTFLoader.LoadExtensionAsync(context, material, this.name, async () => {
      await this._loader.loadMaterialPropertiesAsync(context, material, babylonMaterial);
      new CoatedConductorPlugin(babylonMaterial, model, coatIor, { coatFromMaterial: true });
    });
  }
}

/** Registers the extension with Babylon's glTF loader (every loader made afterwards uses it). */
export function registerCoatedConductorExtension() {
  registerGLTFExtension(EXTENSION_NAME, true, (loader) => new CoatedConductorLoaderExtension(loader));
}

/** Removes it again; true if it was registered. */
export function unregisterCoatedConductorExtension() {
  return unregisterGLTFExtension(EXTENSION_NAME);
}
