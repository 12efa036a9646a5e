#version 430
// The editor's real-time preview (static/preview.js; WebGL2 loads it as
// GLSL ES 3.00, replacing this #version line and adding precision
// statements): a sphere seen by an orbiting perspective camera, reflecting
// an environment, split on screen into up to three vertical bands, each with
// its own Fresnel term: the coated-conductor model from the packed halves,
// adjusted Lazanyi, or the spectral reference from its texture
// (cf_reference_texture.glsl). The camera and environment are shared.
#include "cf_coated_conductor.glsl"
#include "cf_fresnel_baselines.glsl"
#include "cf_environment.glsl"
#include "cf_outdoor.glsl"
#include "cf_reference_texture.glsl"
#include "cf_display.glsl"

const int CF_PANEL_MODEL = 0;
const int CF_PANEL_LAZANYI = 1;
const int CF_PANEL_REFERENCE = 2;

const int CF_OUTPUT_DISPLAY = 0;   // sRGB-encoded, exposed (the canvas)
const int CF_OUTPUT_LINEAR = 1;    // exposed radiance, linear ACEScg
const int CF_OUTPUT_FRESNEL = 2;   // the Fresnel term alone, linear ACEScg
const int CF_OUTPUT_GEOMETRY = 3;  // (NdotV, 1 on the sphere, panel, 1)

uniform vec2 u_resolution;    // pixels
uniform vec3 u_eye;           // camera position (the unit sphere at the origin)
uniform vec3 u_forward;       // unit view direction
uniform vec3 u_right;         // unit right and up, scaled by tan(fov / 2)
uniform vec3 u_up;
uniform int u_panels;         // 1 to 3 bands
uniform ivec3 u_panel_kind;   // CF_PANEL_* of each band, left to right
uniform int u_environment;    // CF_ENVIRONMENT_*
uniform float u_exposure;     // stops
uniform int u_output;         // CF_OUTPUT_*
uniform float u_eta_i;        // index of the coating

uniform uint cf_words[14];
uniform vec2 cf_eta_i_range;
uniform vec3 cf_F0_air;
uniform vec3 cf_F82_air;
uniform sampler2D u_reference;
uniform vec2 u_reference_eta_i_range;

layout(location = 0) out vec4 out_colour;

vec3 cf_preview_environment(int environment, vec3 direction)
{
    if (environment == CF_ENVIRONMENT_OUTDOOR)
        return cf_outdoor_environment(direction);
    return cf_environment(environment, direction);
}

vec3 cf_panel_fresnel(int kind, float NdotV)
{
    if (kind == CF_PANEL_LAZANYI)
        return cf_lazanyi_adjusted(NdotV, u_eta_i, cf_F0_air, cf_F82_air);
    if (kind == CF_PANEL_REFERENCE)
        return cf_reference_lookup(u_reference, NdotV, u_eta_i, u_reference_eta_i_range);
    return cf_coated_conductor_packed(NdotV, u_eta_i, cf_eta_i_range, cf_words);
}

void main()
{
    // A pinhole camera (its basis is computed once on the CPU, see
    // static/preview.js orbitCamera).
    vec3 eye = u_eye;
    vec2 ndc = (2.0 * gl_FragCoord.xy - u_resolution) / u_resolution.y;
    vec3 dir = normalize(u_forward + ndc.x * u_right + ndc.y * u_up);

    int panel = clamp(int(floor(gl_FragCoord.x * float(u_panels) / u_resolution.x)), 0, u_panels - 1);
    int kind = panel == 0 ? u_panel_kind.x : (panel == 1 ? u_panel_kind.y : u_panel_kind.z);

    // Ray against the unit sphere at the origin.
    float b = dot(eye, dir);
    float disc = b * b - (dot(eye, eye) - 1.0);
    vec3 radiance;
    vec3 F = vec3(0.0);
    float NdotV = 0.0;
    float hit = 0.0;
    if (disc > 0.0)
    {
        vec3 N = normalize(eye + (-b - sqrt(disc)) * dir);
        NdotV = cf_saturate(dot(N, -dir));
        F = cf_panel_fresnel(kind, NdotV);
        radiance = F * cf_preview_environment(u_environment, reflect(dir, N));
        hit = 1.0;
    }
    else
        radiance = cf_preview_environment(u_environment, dir);
    radiance *= exp2(u_exposure);

    if (u_output == CF_OUTPUT_LINEAR)
        out_colour = vec4(radiance, 1.0);
    else if (u_output == CF_OUTPUT_FRESNEL)
        out_colour = vec4(F, 1.0);
    else if (u_output == CF_OUTPUT_GEOMETRY)
        out_colour = vec4(NdotV, hit, float(panel), 1.0);
    else
        out_colour = vec4(cf_display(radiance), 1.0);
}
