// evaluate.frag's include for CF_CONSTANTS 1, empty on disk: the host passes
// the material's values as GLSL constants under this name
// (preview_shaders.evaluate.constants_source); with uniforms nothing is needed.
