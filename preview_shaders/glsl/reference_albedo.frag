#version 430
// The reference band's albedo table of the split-sum preview
// (static/preview.js draws it into an n x 1 float target when the
// roughness, eta_i or the reference texture change): texel i holds the
// albedo at NdotV = (i / (n - 1))^2, the nodes cf_albedo_table_lookup
// reads: cf_reference_albedo over u_samples points, or at roughness 0 (a
// mirror) the reference itself.
#include "cf_reference_albedo.glsl"

uniform vec2 u_resolution;
uniform sampler2D u_reference;
uniform vec2 u_reference_eta_i_range;
uniform float u_eta_i;
uniform float u_roughness;
uniform int u_samples;

layout(location = 0) out vec4 out_albedo;

void main()
{
    float s = floor(gl_FragCoord.x) / max(u_resolution.x - 1.0, 1.0);
    vec3 E = u_roughness <= 0.0
        ? cf_reference_lookup(u_reference, s * s, u_eta_i, u_reference_eta_i_range)
        : cf_reference_albedo(u_reference, s * s, u_eta_i, u_reference_eta_i_range, u_roughness, u_samples);
    out_albedo = vec4(E, 1.0);
}
