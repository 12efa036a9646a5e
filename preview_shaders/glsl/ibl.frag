#version 430
// Parity passes of cf_ibl.glsl. CF_IBL_PASS 0: texel (i, j) of slice u_slice
// as texelFetch decodes it. CF_IBL_PASS 1: the model's split sum over a grid,
// column i NdotV = u_grid.x + i u_grid.y, row j roughness = u_grid.z + j u_grid.w;
// the second target holds (NdotV, roughness) as float32.
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
    out_value = vec4(cf_split_sum_model(cf_lut, cf_alpha_range, NdotV, roughness, cf_F0, cf_a, cf_alpha), 1.0);
    out_inputs = vec4(NdotV, roughness, 0.0, 1.0);
#endif
}
