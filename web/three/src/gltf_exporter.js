// The GLTFExporter plugin of EXT_materials_coated_conductor: a scene loaded
// with the extension (gltf_loader.js) is written back with it.

import { EXTENSION_NAME } from "./coated_conductor.js";

/**
 * The GLTFExporter plugin: a material drawing the model (made by the
 * loader plugin or createCoatedConductorMaterial) is written with its
 * EXT_materials_coated_conductor object, and with the fallback's
 * KHR_materials_clearcoat values it was loaded with (three's own exporter
 * writes the coat the plugin draws, `clearcoat` 1, which is not the
 * fallback's fitted factor); the model is not repeated in `extras`.
 *
 *   exporter.register((writer) => new CoatedConductorExporterExtension(writer));
 */
export class CoatedConductorExporterExtension {
  constructor(writer) {
    this.writer = writer;
    this.name = EXTENSION_NAME;
  }

  async writeMaterialAsync(material, materialDef) {
    const data = material.userData?.coatedConductor;
    if (!data?.model) return;
    materialDef.extensions = materialDef.extensions || {};
    materialDef.extensions[this.name] = JSON.parse(JSON.stringify(data.model));
    this.writer.extensionsUsed[this.name] = true;
    for (const [name, values] of Object.entries(data.fallback ?? {})) {
      if (materialDef.extensions[name]) materialDef.extensions[name] = JSON.parse(JSON.stringify(values));
    }
    if (materialDef.extras) {
      delete materialDef.extras.coatedConductor;
      if (Object.keys(materialDef.extras).length === 0) delete materialDef.extras;
    }
  }
}
