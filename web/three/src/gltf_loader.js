// The GLTFLoader plugin of EXT_materials_coated_conductor: a material with
// the extension becomes a MeshPhysicalMaterial drawing the model
// (coated_conductor.js); a malformed or out-of-range extension object draws
// the fallback with a console warning, never an exception.
//
//   loader.register((parser) => new CoatedConductorExtension(parser));

import * as THREE from "three";
import { EXTENSION_NAME, checkModel, coatOf, coatedConductorHooks, loadResources } from "./coated_conductor.js";

/**
 * The GLTFLoader plugin: a material with EXT_materials_coated_conductor
 * becomes a MeshPhysicalMaterial drawing the model (its other properties,
 * read by the loader as usual); without the extension nothing changes. The
 * coat is the material's KHR_materials_clearcoat as three's loader reads it
 * (factor, roughness, their textures), its index the nested draft
 * KHR_materials_clearcoat_ior's clearcoatIor (1.5 without it); without a
 * clear coat the metal is seen from air (coatOf).
 */
export class CoatedConductorExtension {
  constructor(parser) {
    this.parser = parser;
    this.name = EXTENSION_NAME;
    this.checked = new Map(); // material index -> {model, coatIor} checked, or null
  }

  /**
   * Material `materialIndex`'s extension object if it is one this plugin
   * draws (under the material's coat); null without one, and null with a
   * console warning (once per material) for one that fails the schema or
   * the range rules (a coat index outside [1, 3], or outside a polynomial
   * kind's etaIRange): the specification's consumers draw the fallback then.
   */
  model(materialIndex) {
    return this.#checked(materialIndex)?.model ?? null;
  }

  /** The index of the coat material `materialIndex` is drawn under (1: none), or null if it is not drawn. */
  coatIor(materialIndex) {
    return this.#checked(materialIndex)?.coatIor ?? null;
  }

  #checked(materialIndex) {
    if (!this.checked.has(materialIndex)) {
      const def = this.parser.json.materials?.[materialIndex];
      const object = def?.extensions?.[this.name];
      let checked = null;
      if (object !== undefined) {
        try {
          const coatIor = coatOf(def).ior;
          checked = { model: checkModel(object, coatIor), coatIor };
        } catch (error) {
          console.warn(`${error.message}; material ${materialIndex} (${def.name ?? "unnamed"}) draws its fallback`);
        }
      }
      this.checked.set(materialIndex, checked);
    }
    return this.checked.get(materialIndex);
  }

  /** The GLSL and the table, or null with a console warning when they cannot be had. */
  async #resources() {
    try {
      return await loadResources();
    } catch (error) {
      console.warn(`${EXTENSION_NAME}: ${error.message}; the materials draw their fallback`);
      return null;
    }
  }

  getMaterialType(materialIndex) {
    return this.model(materialIndex) ? THREE.MeshPhysicalMaterial : null;
  }

  async extendMaterialParams(materialIndex, materialParams) {
    const model = this.model(materialIndex);
    if (!model) return;
    const resources = await this.#resources();
    if (!resources) return;
    // The clear coat's parameters are three's KHR_materials_clearcoat plugin's.
    Object.assign(materialParams, { metalness: 1 }, coatedConductorHooks(model, resources, this.coatIor(materialIndex)));
  }

  /**
   * The loader puts clones of a material on meshes (assignFinalMaterial:
   * derivative tangents, vertex colours, flat shading), and a clone keeps
   * neither the hooks nor the table: each gets its own here.
   */
  async afterRoot(result) {
    const drawn = (this.parser.json.materials ?? []).some((_, i) => this.model(i));
    const resources = drawn ? await this.#resources() : null;
    if (!resources) return;
    for (const scene of result.scenes ?? [result.scene]) {
      scene.traverse((object) => {
        for (const material of [object.material ?? []].flat()) {
          const index = this.parser.associations.get(material)?.materials;
          const model = index === undefined ? null : this.model(index);
          if (!model || material.userData.coatedConductor?.readTable) continue;
          const { userData, ...hooks } = coatedConductorHooks(model, resources, this.coatIor(index));
          Object.assign(material, hooks);
          Object.assign(material.userData, userData);
        }
      });
    }
  }
}
