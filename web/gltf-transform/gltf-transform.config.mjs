// The gltf-transform CLI with EXT_materials_coated_conductor and the coat's
// index (the draft KHR_materials_clearcoat_ior, nested in the clear coat) kept:
//   gltf-transform optimize in.glb out.glb --config gltf-transform.config.mjs
import { ALL_EXTENSIONS } from "@gltf-transform/extensions";
import { ClearcoatIor, CoatedConductor } from "./coated_conductor.js";

export default { extensions: [...ALL_EXTENSIONS, CoatedConductor, ClearcoatIor] };
