// Types of coated-conductor-three's public API (src/index.js).

import type { Material, MeshPhysicalMaterial, MeshPhysicalMaterialParameters, WebGLRenderer } from "three";
import type { GLTF, GLTFLoaderPlugin, GLTFParser } from "three/examples/jsm/loaders/GLTFLoader.js";
import type { GLTFExporterPlugin, GLTFWriter } from "three/examples/jsm/exporters/GLTFExporter.js";
import type { KindFields, KindName, PackagedKind } from "./generated/kinds.js";

export type { KindFields, KindName, PackagedKind };

/** "EXT_materials_coated_conductor". */
export declare const EXTENSION_NAME: "EXT_materials_coated_conductor";
/** The model kinds the material draws (the project's registry, generated/kinds.js), in its order. */
export declare const KINDS: readonly KindName[];
/** Each kind as the package draws it: parameters, maxDegree, sign rules, generated GLSL. */
export declare const MODEL_KINDS: readonly PackagedKind[];

/** The fields every extension object has, whatever its kind. */
export interface ModelCommon {
  /** The space of the model's reflectance: ACEScg. */
  colorSpace: "ACEScg";
  /** [lo, hi], 1 <= lo <= hi <= 3: the coat indices the model was fitted over. */
  etaIRange: readonly [number, number];
  /** The coat's index of refraction, in [1, 3] (for a kind polynomial in the coat index, inside etaIRange). */
  coatIor: number;
  /** The coat's weight in [0, 1] (default 1). */
  coatFactor?: number;
  /** The coat's roughness in [0, 1] (default 0). */
  coatRoughnessFactor?: number;
  extensions?: Record<string, unknown>;
  extras?: unknown;
}

/** An EXT_materials_coated_conductor extension object. */
export type ExtensionObject = ModelCommon & KindFields;

/** What a material drawing the model carries in `userData.coatedConductor`. */
export interface CoatedConductorData {
  model: ExtensionObject;
  /** The fallback's KHR_materials_clearcoat values it was loaded with, or null. */
  fallback: { KHR_materials_clearcoat: Record<string, unknown> } | null;
  /** The albedo table as drawn (nodes x 3 RGBA floats, row 0 first). */
  readTable(renderer: WebGLRenderer): { nodes: number; data: number[] };
  /** The escape table as drawn (nodes x 2 RGBA floats, row 0 first). */
  readEscape(renderer: WebGLRenderer): { nodes: number; data: number[] };
  /** Frees the tables' render targets (Material.dispose leaves them). */
  dispose(): void;
}

/** The GLSL, the patched chunk, the split-sum table program and the decoded LUT, made once. */
export interface Resources {
  glsl: string;
  pars: string;
  table: string;
  lut: { texture: import("three").Data3DTexture; width: number; alphaRange: [number, number] };
}

/** `model` if it is an extension object the material draws; throws an Error naming the field and the rule. */
export declare function checkModel(model: unknown): ExtensionObject;

/** Loads (once) what every material needs: the first call inflates the LUT. */
export declare function loadResources(): Promise<Resources>;

/** The hooks that make a MeshPhysicalMaterial draw `model`; assign them to the material. */
export declare function coatedConductorHooks(
  model: ExtensionObject,
  resources: Resources,
  fallback?: CoatedConductorData["fallback"],
): Pick<Material, "onBeforeCompile" | "onBeforeRender" | "customProgramCacheKey"> & {
  userData: { coatedConductor: CoatedConductorData };
};

/** A MeshPhysicalMaterial drawing `params.model`; the other params are MeshPhysicalMaterial's. */
export declare function createCoatedConductorMaterial(
  params: MeshPhysicalMaterialParameters & { model: ExtensionObject },
): Promise<MeshPhysicalMaterial>;

/** The GLTFLoader plugin: `loader.register((parser) => new CoatedConductorExtension(parser))`. */
export declare class CoatedConductorExtension implements GLTFLoaderPlugin {
  constructor(parser: GLTFParser);
  readonly name: "EXT_materials_coated_conductor";
  readonly parser: GLTFParser;
  /** Material `materialIndex`'s extension object if it is drawn; null (with a warning once) if malformed. */
  model(materialIndex: number): ExtensionObject | null;
  getMaterialType(materialIndex: number): typeof MeshPhysicalMaterial | null;
  extendMaterialParams(materialIndex: number, materialParams: { [key: string]: any }): Promise<void>;
  fallback(materialIndex: number): CoatedConductorData["fallback"];
  afterRoot(result: GLTF): Promise<void>;
}

/** The GLTFExporter plugin: `exporter.register((writer) => new CoatedConductorExporterExtension(writer))`. */
export declare class CoatedConductorExporterExtension implements GLTFExporterPlugin {
  constructor(writer: GLTFWriter);
  readonly name: "EXT_materials_coated_conductor";
  writeMaterialAsync(material: Material, materialDef: { [key: string]: unknown }): Promise<void>;
}
