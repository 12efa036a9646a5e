// Validate one glTF file with the Khronos glTF validator and print its report
// as JSON on stdout (exit 0 when the report has no errors, 1 otherwise).
// External resources (a .gltf's .bin) are read beside the file.
import { readFileSync } from "node:fs";
import { basename, dirname, join } from "node:path";
import validator from "gltf-validator";

const path = process.argv[2];
if (!path) {
  console.error("usage: node validate.mjs FILE.gltf");
  process.exit(2);
}
const report = await validator.validateBytes(new Uint8Array(readFileSync(path)), {
  uri: basename(path),
  maxIssues: 100,
  externalResourceFunction: async (uri) => new Uint8Array(readFileSync(join(dirname(path), decodeURIComponent(uri)))),
});
console.log(JSON.stringify(report, null, 2));
process.exit(report.issues.numErrors === 0 ? 0 : 1);
