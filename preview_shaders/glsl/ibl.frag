#version 430
// Parity passes of cf_ibl.glsl. CF_IBL_PASS 0: texel (i, j) of slice u_slice
// as texelFetch decodes it. CF_IBL_PASS 1: the model's split sum over a grid,
// column i NdotV = u_grid.x + i u_grid.y, row j roughness = u_grid.z + j u_grid.w;
// the second target holds (NdotV, roughness) as float32. For the cost
// benchmark, on the same grid: CF_IBL_PASS 2 adjusted Lazanyi's split sum
// (cf_F0 the external-medium F0, cf_a from F0 and F82 in air), 3 Schlick's,
// 4 no split sum (the pass's fixed cost).
#include "cf_ibl.glsl"

uniform sampler3D cf_lut;
uniform vec2 cf_alpha_range;
uniform int u_slice;
uniform vec4 u_grid;
uniform vec3 cf_F0;
uniform vec3 cf_a;
uniform vec3 cf_alpha;

layout(location = 0) out vec4 out_value;
layout(location = 1) out vec4 out_inputs;

void main()
{
    ivec2 index = ivec2(floor(gl_FragCoord.xy));
#if CF_IBL_PASS == 0
    out_value = vec4(texelFetch(cf_lut, ivec3(index, u_slice), 0).rgb, 1.0);
    out_inputs = vec4(0.0);
#else
    float NdotV = u_grid.x + float(index.x) * u_grid.y;
    float roughness = u_grid.z + float(index.y) * u_grid.w;
#if CF_IBL_PASS == 1
    vec3 E = cf_split_sum_model(cf_lut, cf_alpha_range, NdotV, roughness, cf_F0, cf_a, cf_alpha);
#elif CF_IBL_PASS == 2
    vec3 E = cf_split_sum_lazanyi(cf_lut, cf_alpha_range, NdotV, roughness, cf_F0, cf_a);
#elif CF_IBL_PASS == 3
    vec3 E = cf_split_sum_schlick(cf_lut, cf_alpha_range, NdotV, roughness, cf_F0);
#else
    // Depends on both inputs, so neither is optimised away.
    vec3 E = vec3(NdotV, roughness, 0.0);
#endif
    out_value = vec4(E, 1.0);
    out_inputs = vec4(NdotV, roughness, 0.0, 1.0);
#endif
}
