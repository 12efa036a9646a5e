#version 430
// The albedo tables of the split-sum preview (static/preview.js draws them
// into an n x 3 float target when the fit, eta_i or a roughness change, not
// per frame): texel (i, row) holds the directional albedo at
// NdotV = (i / (n - 1))^2, the nodes cf_albedo_table_lookup reads. Row 0:
// the model from its packed halves (cf_split_sum_model), row 1: adjusted
// Lazanyi (cf_split_sum_lazanyi), both at u_roughness; row 2: the coat's
// own lobe at u_coat_roughness (cf_split_sum_coat), the same in r, g, b.
// A lobe of roughness 0 is a mirror: its albedo is its Fresnel (the
// model, Lazanyi, the exact dielectric).
#include "cf_coated_conductor.glsl"
#include "cf_fresnel_baselines.glsl"
#include "cf_microfacet.glsl"
#include "cf_ibl.glsl"
#include "cf_ibl_coated.glsl"

uniform vec2 u_resolution;
uniform float u_eta_i;
uniform float u_roughness;
uniform float u_coat_roughness;
uniform uint cf_words[14];
uniform vec2 cf_eta_i_range;
uniform vec3 cf_F0_air;
uniform vec3 cf_F82_air;
uniform sampler3D cf_lut;
uniform vec2 cf_alpha_range;

layout(location = 0) out vec4 out_albedo;

void main()
{
    float s = floor(gl_FragCoord.x) / max(u_resolution.x - 1.0, 1.0);
    float mu = s * s;
    int row = int(floor(gl_FragCoord.y));
    vec3 E;
    if (row == 0)
    {
        mat3 C_F0, C_a, C_alpha;
        vec3 F0, a, alpha;
        cf_unpack_coefficients(cf_words, C_F0, C_a, C_alpha);
        cf_coated_conductor_parameters(cf_normalised_eta_i(u_eta_i, cf_eta_i_range),
                                       C_F0, C_a, C_alpha, F0, a, alpha);
        E = u_roughness <= 0.0
            ? cf_coated_conductor_eq1(mu, F0, a, alpha)
            : cf_split_sum_model(cf_lut, cf_alpha_range, mu, u_roughness, F0, a, alpha);
    }
    else if (row == 1)
    {
        E = u_roughness <= 0.0
            ? cf_lazanyi_adjusted(mu, u_eta_i, cf_F0_air, cf_F82_air)
            : cf_split_sum_lazanyi(cf_lut, cf_alpha_range, mu, u_roughness,
                                   cf_f0_in_medium(cf_F0_air, u_eta_i), cf_lazanyi_a(cf_F0_air, cf_F82_air));
    }
    else
    {
        E = vec3(u_coat_roughness <= 0.0
            ? cf_fresnel_dielectric(mu, max(u_eta_i, 1.0))
            : cf_split_sum_coat(cf_lut, cf_alpha_range, mu, u_coat_roughness, u_eta_i));
    }
    out_albedo = vec4(E, 1.0);
}
