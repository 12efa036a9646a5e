#version 430
// The preview sphere: a smooth sphere seen by an orthographic camera on +z,
// reflecting the environment. Columns left of u_split_column show the
// material's model kind (cf_preview_model from cf_words: the include is made
// per kind by preview_shaders/kinds.py from fitting.models.kinds), the others
// the comparison (adjusted Lazanyi), as in Vernooij 2024, Figure 2. Output in
// linear ACEScg.
#include "cf_preview_model.glsl"
#include "cf_fresnel_baselines.glsl"
#include "cf_environment.glsl"

uniform vec2 u_centre;        // sphere centre in pixels
uniform float u_radius;       // sphere radius in pixels
uniform float u_split_column; // first column of the comparison
uniform int u_environment;    // CF_ENVIRONMENT_*
uniform float u_eta_i;        // index of the coating

uniform uint cf_words[14];    // the kind's float16 coefficients, two per word, zero-padded
uniform vec2 cf_eta_i_range;
uniform vec3 cf_F0_air;
uniform vec3 cf_F82_air;

layout(location = 0) out vec4 out_colour;   // linear ACEScg
layout(location = 1) out vec4 out_geometry; // (NdotV, 1 on the sphere, 0, 1)
layout(location = 2) out vec4 out_radiance; // environment radiance behind the pixel

void main()
{
    vec2 p = (gl_FragCoord.xy - u_centre) / u_radius;
    float r2 = dot(p, p);
    if (r2 >= 1.0)
    {
        // Background: the environment seen through a mild perspective, so the
        // studio shows its gradient (the white sky is 1 everywhere).
        vec3 L = cf_environment(u_environment, vec3(0.5 * p, -1.0));
        out_colour = vec4(L, 1.0);
        out_geometry = vec4(0.0, 0.0, 0.0, 1.0);
        out_radiance = vec4(L, 1.0);
        return;
    }
    vec3 N = vec3(p, sqrt(1.0 - r2));
    const vec3 V = vec3(0.0, 0.0, 1.0);
    float NdotV = N.z;
    // Mirror direction of a smooth surface.
    vec3 R = 2.0 * NdotV * N - V;
    vec3 L = cf_environment(u_environment, R);
    vec3 F;
    if (gl_FragCoord.x < u_split_column)
        F = cf_preview_model(NdotV, u_eta_i, cf_eta_i_range, cf_words);
    else
        F = cf_lazanyi_adjusted(NdotV, u_eta_i, cf_F0_air, cf_F82_air);
    out_colour = vec4(F * L, 1.0);
    out_geometry = vec4(NdotV, 1.0, 0.0, 1.0);
    out_radiance = vec4(L, 1.0);
}
