// EXT_materials_coated_conductor for glTF Transform (@gltf-transform/core 4):
// the extension read into each material as a CoatedConductorMaterial
// (its object kept as it is in the file: kind, colorSpace, etaIRange,
// degree, coefficients) and written back, so that scripts and the
// gltf-transform CLI keep it (specification:
// docs/gltf/EXT_materials_coated_conductor/). The coat the metal lies under
// is the material's KHR_materials_clearcoat (glTF Transform's own
// extension keeps it) with its index in the draft KHR_materials_clearcoat_ior
// nested in it, which glTF Transform does not know: ClearcoatIor keeps it.
//
//   import { NodeIO } from "@gltf-transform/core";
//   import { CoatedConductor } from "coated-conductor-gltf-transform";
//   const io = new NodeIO().registerExtensions([CoatedConductor]);
//   const document = await io.read("coated.gltf");
//   material.getExtension("EXT_materials_coated_conductor").getModel();
//   material.getExtension("KHR_materials_clearcoat_ior")?.getClearcoatIor();  // the coat's index
//
// The CLI: gltf-transform optimize in.glb out.glb --config gltf-transform.config.mjs

import { Extension, ExtensionProperty, PropertyType } from "@gltf-transform/core";

export const EXTENSION_NAME = "EXT_materials_coated_conductor";
export const CLEARCOAT_IOR = "KHR_materials_clearcoat_ior";
const CLEARCOAT = "KHR_materials_clearcoat";

// A deep copy of a JSON value (the extension object is plain JSON).
const copy = (value) => JSON.parse(JSON.stringify(value));

/** The extension on one material: `getModel()` / `setModel(object)`, the object as the file has it. */
export class CoatedConductorMaterial extends ExtensionProperty {
  static EXTENSION_NAME = EXTENSION_NAME;

  init() {
    this.extensionName = EXTENSION_NAME;
    this.propertyType = "CoatedConductor";
    this.parentTypes = [PropertyType.MATERIAL];
  }

  getDefaults() {
    return Object.assign(super.getDefaults(), { model: null });
  }

  /** The extension object (a copy: edit it and setModel it back). */
  getModel() {
    const model = this.get("model");
    return model === null ? null : copy(model);
  }

  /** Set the extension object (copied). */
  setModel(model) {
    return this.set("model", model === null ? null : copy(model));
  }
}

/** The glTF Transform extension: register it on an IO, or in the CLI's config (gltf-transform.config.mjs). */
export class CoatedConductor extends Extension {
  static EXTENSION_NAME = EXTENSION_NAME;
  extensionName = EXTENSION_NAME;

  /** A new CoatedConductorMaterial for `material.setExtension(EXTENSION_NAME, ...)`. */
  createCoatedConductor() {
    return new CoatedConductorMaterial(this.document.getGraph());
  }

  read(context) {
    const definitions = context.jsonDoc.json.materials || [];
    definitions.forEach((definition, index) => {
      const object = definition.extensions?.[EXTENSION_NAME];
      if (object && typeof object === "object") {
        context.materials[index].setExtension(EXTENSION_NAME, this.createCoatedConductor().setModel(object));
      }
    });
    return this;
  }

  write(context) {
    const json = context.jsonDoc.json;
    for (const material of this.document.getRoot().listMaterials()) {
      const extension = material.getExtension(EXTENSION_NAME);
      const model = extension?.getModel();
      if (!model) continue;
      const definition = json.materials[context.materialIndexMap.get(material)];
      definition.extensions = definition.extensions || {};
      definition.extensions[EXTENSION_NAME] = model;
    }
    return this;
  }
}

/** The coat's index on one material (KHR_materials_clearcoat_ior): `getClearcoatIor()` / `setClearcoatIor(x)`. */
export class ClearcoatIorMaterial extends ExtensionProperty {
  static EXTENSION_NAME = CLEARCOAT_IOR;

  init() {
    this.extensionName = CLEARCOAT_IOR;
    this.propertyType = "ClearcoatIor";
    this.parentTypes = [PropertyType.MATERIAL];
  }

  getDefaults() {
    return Object.assign(super.getDefaults(), { clearcoatIor: 1.5 });
  }

  getClearcoatIor() {
    return this.get("clearcoatIor");
  }

  setClearcoatIor(ior) {
    return this.set("clearcoatIor", ior);
  }
}

/**
 * The draft KHR_materials_clearcoat_ior (KhronosGroup/glTF pull request
 * 2530): the clear coat's index, an extension nested in the material's
 * KHR_materials_clearcoat object. Read into a ClearcoatIorMaterial on the
 * material and written back into the clear coat's object (glTF Transform
 * writes extensions sorted by name: KHR_materials_clearcoat's first); a
 * material without a clear coat writes none.
 */
export class ClearcoatIor extends Extension {
  static EXTENSION_NAME = CLEARCOAT_IOR;
  extensionName = CLEARCOAT_IOR;

  createClearcoatIor() {
    return new ClearcoatIorMaterial(this.document.getGraph());
  }

  read(context) {
    (context.jsonDoc.json.materials || []).forEach((definition, index) => {
      const object = definition.extensions?.[CLEARCOAT]?.extensions?.[CLEARCOAT_IOR];
      if (object && typeof object === "object" && typeof object.clearcoatIor === "number") {
        context.materials[index].setExtension(CLEARCOAT_IOR, this.createClearcoatIor().setClearcoatIor(object.clearcoatIor));
      }
    });
    return this;
  }

  write(context) {
    const json = context.jsonDoc.json;
    for (const material of this.document.getRoot().listMaterials()) {
      const ior = material.getExtension(CLEARCOAT_IOR);
      const clearcoat = json.materials[context.materialIndexMap.get(material)]?.extensions?.[CLEARCOAT];
      if (!ior || !clearcoat) continue;
      clearcoat.extensions = clearcoat.extensions || {};
      clearcoat.extensions[CLEARCOAT_IOR] = { clearcoatIor: ior.getClearcoatIor() };
    }
    return this;
  }
}
