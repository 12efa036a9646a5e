#version 430
// The albedo table of an rgb-conductor material (static/three/coated_conductor.js
// draws it into an n x 3 float target when eta_i or a roughness change),
// laid out as albedo_table.frag's so that cf_albedo_table_lookup reads
// both: texel (i, row) at NdotV = (i / (n - 1))^2. Row 0: the metal's lobe
// at u_roughness (cf_rgb_conductor_albedo over u_samples points; at
// roughness 0 a mirror, its Fresnel); row 1: 0 (no baseline); row 2: the
// coat's own lobe at u_coat_roughness, as albedo_table.frag's.
#include "cf_rgb_conductor_albedo.glsl"
#include "cf_ibl.glsl"
#include "cf_ibl_coated.glsl"

uniform vec2 u_resolution;
uniform float u_eta_i;
uniform float u_roughness;
uniform float u_coat_roughness;
uniform vec3 cf_n;
uniform vec3 cf_k;
uniform int u_samples;
uniform sampler3D cf_lut;
uniform vec2 cf_alpha_range;

layout(location = 0) out vec4 out_albedo;

void main()
{
    float s = floor(gl_FragCoord.x) / max(u_resolution.x - 1.0, 1.0);
    float mu = s * s;
    int row = int(floor(gl_FragCoord.y));
    vec3 E = vec3(0.0);
    if (row == 0)
    {
        E = u_roughness <= 0.0
            ? cf_rgb_conductor(mu, u_eta_i, cf_n, cf_k)
            : cf_rgb_conductor_albedo(mu, u_eta_i, cf_n, cf_k, u_roughness, u_samples);
    }
    else if (row == 2)
    {
        E = vec3(u_coat_roughness <= 0.0
            ? cf_fresnel_dielectric(mu, max(u_eta_i, 1.0))
            : cf_split_sum_coat(cf_lut, cf_alpha_range, mu, u_coat_roughness, u_eta_i));
    }
    out_albedo = vec4(E, 1.0);
}
