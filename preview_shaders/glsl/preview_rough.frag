#version 430
// The rough preview sphere: the sphere of preview.frag with a
// GGX lobe of perceptual roughness u_roughness, lit by image-based lighting
// through the split sum (Karis 2013): the directional albedo from the
// pre-integrated LUT (cf_ibl.glsl) times the environment prefiltered at the
// lobe's roughness (u_prefiltered: equirect slices, one per roughness node,
// made by preview_shaders/rough.py). Modes: u_mode 0 immersed (the camera
// in the medium of index u_eta_i), 1 coated (a clear coat of index u_eta_i
// seen from air, cf_ibl_coated.glsl: the coat's Schlick lobe at
// u_coat_roughness plus the base's albedo at the refracted cosine,
// transmitted in and out). Columns left of u_split_column show the model,
// the others adjusted Lazanyi under the same lighting. Output linear ACEScg.
#include "cf_coated_conductor.glsl"
#include "cf_fresnel_baselines.glsl"
#include "cf_environment.glsl"
#include "cf_microfacet.glsl"
#include "cf_ibl.glsl"
#include "cf_ibl_coated.glsl"
#include "cf_prefiltered_environment.glsl"

uniform vec2 u_centre;        // sphere centre in pixels
uniform float u_radius;       // sphere radius in pixels
uniform float u_split_column; // first column of the comparison
uniform int u_environment;    // CF_ENVIRONMENT_*
uniform float u_eta_i;        // index of the medium / coat
uniform int u_mode;           // 0 immersed, 1 coated
uniform float u_roughness;    // base, [0, 1]
uniform float u_coat_roughness;

uniform uint cf_words[14];
uniform vec2 cf_eta_i_range;
uniform vec3 cf_F0_air;
uniform vec3 cf_F82_air;
uniform sampler3D cf_lut;
uniform vec2 cf_alpha_range;
uniform sampler3D u_prefiltered; // (u, v, roughness node), linear filtering

layout(location = 0) out vec4 out_colour;    // linear ACEScg
layout(location = 1) out vec4 out_geometry;  // (NdotV, 1 on the sphere, 0, 1)
layout(location = 2) out vec4 out_radiance;  // prefiltered at u_roughness
layout(location = 3) out vec4 out_coat_radiance; // prefiltered at u_coat_roughness

vec3 cf_prefiltered(vec3 R, float roughness)
{
    ivec3 size = textureSize(u_prefiltered, 0);
    float z = (cf_saturate(roughness) * float(size.z - 1) + 0.5) / float(size.z);
    return texture(u_prefiltered, vec3(cf_equirect_uv(R), z)).rgb;
}

void main()
{
    vec2 p = (gl_FragCoord.xy - u_centre) / u_radius;
    float r2 = dot(p, p);
    if (r2 >= 1.0)
    {
        vec3 L = cf_environment(u_environment, vec3(0.5 * p, -1.0));
        out_colour = vec4(L, 1.0);
        out_geometry = vec4(0.0, 0.0, 0.0, 1.0);
        out_radiance = vec4(L, 1.0);
        out_coat_radiance = vec4(L, 1.0);
        return;
    }
    vec3 N = vec3(p, sqrt(1.0 - r2));
    const vec3 V = vec3(0.0, 0.0, 1.0);
    float NdotV = N.z;
    vec3 R = 2.0 * NdotV * N - V;
    vec3 L_base = cf_prefiltered(R, u_roughness);
    vec3 L_coat = cf_prefiltered(R, u_coat_roughness);

    vec3 F0, a, alpha;
    if (gl_FragCoord.x < u_split_column)
    {
        mat3 C_F0, C_a, C_alpha;
        cf_unpack_coefficients(cf_words, C_F0, C_a, C_alpha);
        cf_coated_conductor_parameters(cf_normalised_eta_i(u_eta_i, cf_eta_i_range),
                                       C_F0, C_a, C_alpha, F0, a, alpha);
    }
    else
    {
        // Adjusted Lazanyi: F0 in the medium, a from F0 and F82 in air, alpha 6.
        F0 = cf_f0_in_medium(cf_F0_air, u_eta_i);
        a = cf_lazanyi_a(cf_F0_air, cf_F82_air);
        alpha = vec3(6.0);
    }
    vec3 colour;
    if (u_mode == 0)
    {
        colour = cf_split_sum_model(cf_lut, cf_alpha_range, NdotV, u_roughness, F0, a, alpha) * L_base;
    }
    else
    {
        float coat = cf_split_sum_coat(cf_lut, cf_alpha_range, NdotV, u_coat_roughness, u_eta_i);
        float mu_t = cf_cos_in_coat(NdotV, u_eta_i);
        vec3 base = cf_split_sum_model(cf_lut, cf_alpha_range, mu_t, u_roughness, F0, a, alpha);
        colour = coat * L_coat + cf_coat_transmission(NdotV, u_eta_i) * base * L_base;
    }
    out_colour = vec4(colour, 1.0);
    out_geometry = vec4(NdotV, 1.0, 0.0, 1.0);
    out_radiance = vec4(L_base, 1.0);
    out_coat_radiance = vec4(L_coat, 1.0);
}
