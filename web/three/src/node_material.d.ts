// Types of coated-conductor-three/webgpu (src/node_material.js): the node material.

import type { Material, Object3D } from "three";
import type { MeshPhysicalNodeMaterial, MeshPhysicalNodeMaterialParameters } from "three/webgpu";
import type { ExtensionObject, Resources } from "./index.js";

/** What a node material drawing the model carries in `userData.coatedConductor`. */
export interface CoatedConductorNodeData {
  model: ExtensionObject;
  /** The index of the clear coat the metal lies under (1: none). */
  coatIor: number;
  /** The fallback's KHR_materials_clearcoat values the glTF material was loaded with, or null. */
  fallback: { KHR_materials_clearcoat: Record<string, unknown> } | null;
  /** Frees the tables (their off-screen render targets and DataTextures). */
  dispose(): void;
}

/**
 * A MeshPhysicalNodeMaterial drawing the coated metal `model` with three's
 * node materials (WebGPURenderer on WebGPU or its WebGL2 backend).
 */
export declare class CoatedConductorNodeMaterial extends MeshPhysicalNodeMaterial {
  constructor(
    model: ExtensionObject, resources: Resources, parameters?: MeshPhysicalNodeMaterialParameters, coatIor?: number,
  );
  readonly isCoatedConductorNodeMaterial: true;
  userData: { coatedConductor: CoatedConductorNodeData; [key: string]: unknown };
}

/** A CoatedConductorNodeMaterial drawing `params.model` under a coat of index `params.coatIor` (default 1.5). */
export declare function createCoatedConductorNodeMaterial(
  params: MeshPhysicalNodeMaterialParameters & { model: ExtensionObject; coatIor?: number },
): Promise<CoatedConductorNodeMaterial>;

/** The node-material twin of a material the GLTFLoader plugin made; any other material as it is. */
export declare function toCoatedConductorNodeMaterial<M extends Material>(
  material: M,
): Promise<M | CoatedConductorNodeMaterial>;

/** Replace, in place, every coated material under `root` by its node-material twin; `root`. */
export declare function useCoatedConductorNodeMaterials<T extends Object3D>(root: T): Promise<T>;

/** Each kind's TSL twin of its GLSL Fresnel, by GLSL function name (node_models.js). */
export declare const NODE_MODELS: Readonly<Record<string, unknown>>;
