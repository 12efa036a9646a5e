// Types of coated-conductor-three's public API (src/index.js).

import type { Material, MeshPhysicalMaterial, MeshPhysicalMaterialParameters, WebGLRenderer } from "three";
import type { GLTF, GLTFLoaderPlugin, GLTFParser } from "three/examples/jsm/loaders/GLTFLoader.js";
import type { GLTFExporterPlugin, GLTFWriter } from "three/examples/jsm/exporters/GLTFExporter.js";
import type { KindFields, KindName, PackagedKind } from "./generated/kinds.js";

export type { KindFields, KindName, PackagedKind };

/** "EXT_materials_coated_conductor". */
export declare const EXTENSION_NAME: "EXT_materials_coated_conductor";
/** "KHR_materials_clearcoat_ior": the draft carrying the clear coat's index, nested in KHR_materials_clearcoat. */
export declare const CLEARCOAT_IOR: "KHR_materials_clearcoat_ior";
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
  extensions?: Record<string, unknown>;
  extras?: unknown;
}

/** An EXT_materials_coated_conductor extension object. */
export type ExtensionObject = ModelCommon & KindFields;

/** What a material drawing the model carries in `userData.coatedConductor`. */
export interface CoatedConductorData {
  model: ExtensionObject;
  /** The index of the clear coat the metal is drawn under (1: no coat, the metal in air). */
  coatIor: number;
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

/**
 * `model` if it is an extension object the material draws under a coat of index `coatIor`
 * (default 1.5; 1: no coat); throws an Error naming the field and the rule.
 */
export declare function checkModel(model: unknown, coatIor?: number): ExtensionObject;

/** The coat a glTF material definition composes the extension with (no clear coat: factor 0, index 1). */
export declare function coatOf(definition: unknown): { factor: number; ior: number };

/** Loads (once) what every material needs: the first call inflates the LUT. */
export declare function loadResources(): Promise<Resources>;

/** The hooks that make a MeshPhysicalMaterial draw `model`; assign them to the material. */
export declare function coatedConductorHooks(
  model: ExtensionObject,
  resources: Resources,
  coatIor?: number,
): Pick<Material, "onBeforeCompile" | "onBeforeRender" | "customProgramCacheKey"> & {
  userData: { coatedConductor: CoatedConductorData };
};

/**
 * A MeshPhysicalMaterial drawing `params.model` under a clear coat of index `params.coatIor`
 * (default 1.5); the other params are MeshPhysicalMaterial's (clearcoat 0: no coat).
 */
export declare function createCoatedConductorMaterial(
  params: MeshPhysicalMaterialParameters & { model: ExtensionObject; coatIor?: number },
): Promise<MeshPhysicalMaterial>;

/** The GLTFLoader plugin: `loader.register((parser) => new CoatedConductorExtension(parser))`. */
export declare class CoatedConductorExtension implements GLTFLoaderPlugin {
  constructor(parser: GLTFParser);
  readonly name: "EXT_materials_coated_conductor";
  readonly parser: GLTFParser;
  /** Material `materialIndex`'s extension object if it is drawn; null (with a warning once) if malformed. */
  model(materialIndex: number): ExtensionObject | null;
  /** The index of the coat a drawn material lies under (1: none), or null if it is not drawn. */
  coatIor(materialIndex: number): number | null;
  getMaterialType(materialIndex: number): typeof MeshPhysicalMaterial | null;
  extendMaterialParams(materialIndex: number, materialParams: { [key: string]: any }): Promise<void>;
  afterRoot(result: GLTF): Promise<void>;
}

/** The GLTFExporter plugin: `exporter.register((writer) => new CoatedConductorExporterExtension(writer))`. */
export declare class CoatedConductorExporterExtension implements GLTFExporterPlugin {
  constructor(writer: GLTFWriter);
  readonly name: "EXT_materials_coated_conductor";
  writeMaterialAsync(material: Material, materialDef: { [key: string]: unknown }): Promise<void>;
}
