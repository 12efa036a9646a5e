#version 430
// Full-screen evaluation of the microfacet BRDF over a grid of directions
// for the parity tests: column i has theta_v = u_grid.x + i u_grid.y, row j
// theta_l = u_grid.z + j u_grid.w, the light at azimuth u_phi from the view.
// CF_MODE 0 immersed, 1 coated. Writes the BRDF and the float32 V and L it
// used, so numpy evaluates the same directions.
#include "cf_microfacet.glsl"

uniform vec4 u_grid;
uniform float u_phi;
uniform float cf_roughness;
uniform float cf_coat_roughness;
uniform float cf_eta_i;
uniform vec3 cf_F0;
uniform vec3 cf_a;
uniform vec3 cf_alpha;

layout(location = 0) out vec4 out_f;
layout(location = 1) out vec4 out_V;
layout(location = 2) out vec4 out_L;

void main()
{
    vec2 index = floor(gl_FragCoord.xy);
    float theta_v = u_grid.x + index.x * u_grid.y;
    float theta_l = u_grid.z + index.y * u_grid.w;
    vec3 V = vec3(sin(theta_v), 0.0, cos(theta_v));
    vec3 L = vec3(sin(theta_l) * cos(u_phi), sin(theta_l) * sin(u_phi), cos(theta_l));
#if CF_MODE == 0
    vec3 f = cf_microfacet_immersed(V, L, cf_roughness, cf_F0, cf_a, cf_alpha);
#else
    vec3 f = cf_microfacet_coated(V, L, cf_roughness, cf_F0, cf_a, cf_alpha, cf_eta_i,
                                  cf_coat_roughness);
#endif
    out_f = vec4(f, 1.0);
    out_V = vec4(V, 1.0);
    out_L = vec4(L, 1.0);
}
