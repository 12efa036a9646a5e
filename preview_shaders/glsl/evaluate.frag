#version 430
// Full-screen evaluation of one Fresnel variant over a grid of
// (cos theta, eta_i): column i has NdotV = grid.x + i grid.y, row j has
// eta_i = grid.z + j grid.w. CF_VARIANT is set by the host:
// 0 model from packed halves, 1 model from floats, 2 scene-specialised model,
// 3 adjusted Lazanyi, 4 Schlick, 5 exact RGB conductor Fresnel from floats,
// 6 the rgb-conductor kind from packed halves, 7 the lean general model
// (per-power coefficients and the t map from the CPU), 8 the lean
// scene-specialised model, 9 adjusted Lazanyi with n and a from the CPU;
// for the cost benchmark only: 10 Lazanyi at a scene-constant eta_i (F0 and
// a from the CPU), 11 no Fresnel term (the pass's fixed cost:
// rasterisation, the grid inputs, the store).
#include "cf_coated_conductor.glsl"
#include "cf_rgb_conductor.glsl"
#include "cf_fresnel_baselines.glsl"

uniform vec4 u_grid;

#if CF_VARIANT == 0
uniform uint cf_words[14];
uniform vec2 cf_eta_i_range;
#elif CF_VARIANT == 1
// The 27 coefficients as floats, one mat3 per parameter, column c channel c.
uniform mat3 cf_C_F0;
uniform mat3 cf_C_a;
uniform mat3 cf_C_alpha;
uniform vec2 cf_eta_i_range;
#elif CF_VARIANT == 2
uniform vec3 cf_F0;
uniform vec3 cf_a;
uniform vec3 cf_alpha;
#elif CF_VARIANT == 3
uniform vec3 cf_F0_air;
uniform vec3 cf_F82_air;
#elif CF_VARIANT == 4
uniform vec3 cf_F0;
#elif CF_VARIANT == 5
uniform vec3 cf_n;
uniform vec3 cf_k;
#elif CF_VARIANT == 6
uniform uint cf_rgb_words[3];
#elif CF_VARIANT == 7
// Column j: power j of t for the three channels.
uniform mat3 cf_P_F0;
uniform mat3 cf_P_a;
uniform mat3 cf_P_alpha;
uniform vec2 cf_t_map;
#elif CF_VARIANT == 8
uniform vec3 cf_F0;
uniform vec3 cf_a;
uniform vec3 cf_alpha;
#elif CF_VARIANT == 9
uniform vec3 cf_n_equivalent;
uniform vec3 cf_a;
#elif CF_VARIANT == 10
uniform vec3 cf_F0;
uniform vec3 cf_a;
#endif

layout(location = 0) out vec4 out_F;
#if CF_WRITE_INPUTS
layout(location = 1) out vec4 out_inputs;
#endif

void main()
{
    vec2 index = floor(gl_FragCoord.xy);
    float NdotV = u_grid.x + index.x * u_grid.y;
    float eta_i = u_grid.z + index.y * u_grid.w;
#if CF_VARIANT == 0
    vec3 F = cf_coated_conductor_packed(NdotV, eta_i, cf_eta_i_range, cf_words);
#elif CF_VARIANT == 1
    vec3 F = cf_coated_conductor(NdotV, eta_i, cf_eta_i_range, cf_C_F0, cf_C_a, cf_C_alpha);
#elif CF_VARIANT == 2
    vec3 F = cf_coated_conductor_eq1(NdotV, cf_F0, cf_a, cf_alpha);
#elif CF_VARIANT == 3
    vec3 F = cf_lazanyi_adjusted(NdotV, eta_i, cf_F0_air, cf_F82_air);
#elif CF_VARIANT == 4
    vec3 F = cf_schlick(NdotV, cf_F0);
#elif CF_VARIANT == 5
    vec3 F = cf_fresnel_conductor(NdotV, eta_i, cf_n, cf_k);
#elif CF_VARIANT == 6
    vec3 F = cf_rgb_conductor_packed(NdotV, eta_i, cf_rgb_words);
#elif CF_VARIANT == 7
    vec3 F = cf_coated_conductor_lean(NdotV, eta_i, cf_t_map, cf_P_F0, cf_P_a, cf_P_alpha);
#elif CF_VARIANT == 8
    vec3 F = cf_coated_conductor_eq1_lean(NdotV, cf_F0, cf_a, cf_alpha);
#elif CF_VARIANT == 9
    vec3 F = cf_lazanyi_adjusted_lean(NdotV, eta_i, cf_n_equivalent, cf_a);
#elif CF_VARIANT == 10
    vec3 F = cf_lazanyi(NdotV, cf_F0, cf_a);
#elif CF_VARIANT == 11
    // Depends on both inputs, so neither is optimised away.
    vec3 F = vec3(NdotV, eta_i, 0.0);
#endif
    out_F = vec4(F, 1.0);
#if CF_WRITE_INPUTS
    out_inputs = vec4(NdotV, eta_i, 0.0, 1.0);
#endif
}
