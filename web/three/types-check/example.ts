// A small program using the package's API, type-checked by
// `tsc --noEmit -p types-check` (tests/static/test_three_package.py).
import * as THREE from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { GLTFExporter } from "three/examples/jsm/exporters/GLTFExporter.js";
import {
  CoatedConductorExporterExtension, CoatedConductorExtension, EXTENSION_NAME, checkModel,
  createCoatedConductorMaterial, type ExtensionObject,
} from "coated-conductor-three";

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

// The types are real: each line below must be an error (tsc fails on an unused directive).
// @ts-expect-error: "schlick" is not a model kind
export const notAKind: ExtensionObject = { ...gold, kind: "schlick" };
// @ts-expect-error: the material needs its model
export const noModel = createCoatedConductorMaterial({ roughness: 0.3 });
// @ts-expect-error: the coat is the clear coat's, not the extension's (revision 1's coatIor is gone)
export const oldCoat: ExtensionObject = { ...gold, coatIor: 1.5 };
