// The GLTFExporter plugin of EXT_materials_coated_conductor: a scene loaded
// with the extension (gltf_loader.js) is written back with it.

import { CLEARCOAT_IOR, EXTENSION_NAME } from "./coated_conductor.js";

/**
 * The GLTFExporter plugin: a material drawing the model (made by the
 * loader plugin or createCoatedConductorMaterial) is written with its
 * EXT_materials_coated_conductor object; its clear coat (three's own
 * exporter writes KHR_materials_clearcoat from the material's clearcoat
 * parameters and maps) gets the coat's index in the nested draft
 * KHR_materials_clearcoat_ior, which three does not write; the model is not
 * repeated in `extras`.
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
    const clearcoat = materialDef.extensions.KHR_materials_clearcoat;
    if (clearcoat && data.coatIor > 1) {
      clearcoat.extensions = { ...clearcoat.extensions, [CLEARCOAT_IOR]: { clearcoatIor: data.coatIor } };
      this.writer.extensionsUsed[CLEARCOAT_IOR] = true;
    }
    if (materialDef.extras) {
      delete materialDef.extras.coatedConductor;
      if (Object.keys(materialDef.extras).length === 0) delete materialDef.extras;
    }
  }
}
