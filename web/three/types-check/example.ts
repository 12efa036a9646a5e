// A small program using the package's API, type-checked by
// `tsc --noEmit -p types-check` (tests/static/test_three_package.py).
import * as THREE from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { GLTFExporter } from "three/examples/jsm/exporters/GLTFExporter.js";
import {
  CoatedConductorExporterExtension, CoatedConductorExtension, EXTENSION_NAME, checkModel,
  createCoatedConductorMaterial, type ExtensionObject,
} from "coated-conductor-three";
import {
  CoatedConductorNodeMaterial, createCoatedConductorNodeMaterial, useCoatedConductorNodeMaterials,
} from "coated-conductor-three/webgpu";
import { WebGPURenderer } from "three/webgpu";

const gold: ExtensionObject = {
  kind: "rgb-conductor", colorSpace: "ACEScg", etaIRange: [1, 2.5],
  coefficients: { n: [0.18, 0.42, 1.37], k: [3.42, 2.35, 1.77] },
};

export async function draw(renderer: THREE.WebGLRenderer, url: string): Promise<THREE.MeshPhysicalMaterial> {
  const loader = new GLTFLoader();
  loader.register((parser) => new CoatedConductorExtension(parser));
  const gltf = await loader.loadAsync(url);
  const exporter = new GLTFExporter();
  exporter.register((writer) => new CoatedConductorExporterExtension(writer));
  const written = await exporter.parseAsync(gltf.scene, { binary: false });
  console.log(EXTENSION_NAME, Object.keys(written));
  const material = await createCoatedConductorMaterial({ model: checkModel(gold, 1.8), coatIor: 1.8, roughness: 0.3 });
  const data = material.userData.coatedConductor;
  if (data) console.log(data.readTable(renderer).nodes);
  return material;
}

// The same scene with three's node materials (WebGPURenderer; its WebGL2 backend where there is no WebGPU).
export async function drawNodes(url: string): Promise<CoatedConductorNodeMaterial> {
  const renderer = new WebGPURenderer({ forceWebGL: true });
  await renderer.init();
  const loader = new GLTFLoader();
  loader.register((parser) => new CoatedConductorExtension(parser));
  const gltf = await loader.loadAsync(url);
  await useCoatedConductorNodeMaterials(gltf.scene);
  const material = await createCoatedConductorNodeMaterial({ model: gold, roughness: 0.3, clearcoatRoughness: 0.1 });
  console.log(material.isCoatedConductorNodeMaterial, material.userData.coatedConductor.model.kind);
  return material;
}

// The types are real: each line below must be an error (tsc fails on an unused directive).
// @ts-expect-error: "schlick" is not a model kind
export const notAKind: ExtensionObject = { ...gold, kind: "schlick" };
// @ts-expect-error: the material needs its model
export const noModel = createCoatedConductorMaterial({ roughness: 0.3 });
// @ts-expect-error: the node material needs its model too
export const noNodeModel = createCoatedConductorNodeMaterial({ roughness: 0.3 });
// @ts-expect-error: the coat is the clear coat's, not the extension's (revision 1's coatIor is gone)
export const oldCoat: ExtensionObject = { ...gold, coatIor: 1.5 };
