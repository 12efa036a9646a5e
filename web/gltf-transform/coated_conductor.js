// EXT_materials_coated_conductor for glTF Transform (@gltf-transform/core 4):
// the extension read into each material as a CoatedConductorMaterial
// (its object kept as it is in the file: kind, colorSpace, etaIRange,
// degree, coefficients, coatIor, coatFactor, coatRoughnessFactor) and
// written back, so that scripts and the gltf-transform CLI keep it
// (specification: docs/gltf/EXT_materials_coated_conductor/).
//
//   import { NodeIO } from "@gltf-transform/core";
//   import { CoatedConductor } from "coated-conductor-gltf-transform";
//   const io = new NodeIO().registerExtensions([CoatedConductor]);
//   const document = await io.read("coated.gltf");
//   material.getExtension("EXT_materials_coated_conductor").getModel();
//
// The CLI: gltf-transform optimize in.glb out.glb --config gltf-transform.config.mjs

import { Extension, ExtensionProperty, PropertyType } from "@gltf-transform/core";

export const EXTENSION_NAME = "EXT_materials_coated_conductor";

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
