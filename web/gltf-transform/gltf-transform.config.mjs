// The gltf-transform CLI with EXT_materials_coated_conductor kept:
//   gltf-transform optimize in.glb out.glb --config gltf-transform.config.mjs
import { ALL_EXTENSIONS } from "@gltf-transform/extensions";
import { CoatedConductor } from "./coated_conductor.js";

export default { extensions: [...ALL_EXTENSIONS, CoatedConductor] };
