#version 430
// The editor's real-time preview (static/preview.js; WebGL2 loads it as
// GLSL ES 3.00, replacing this #version line and adding precision
// statements): a sphere seen by an orbiting perspective camera, reflecting
// an environment, split on screen into up to three vertical bands, each with
// its own Fresnel term: the coated-conductor model from the packed halves,
// adjusted Lazanyi, or the spectral reference from its texture
// (cf_reference_texture.glsl). The camera and environment are shared.
//
// The metal's GGX lobe has perceptual roughness u_roughness, the coat's
// u_coat_roughness. u_coated 0: the camera sits in the coat's medium of
// index u_eta_i (the paper's set-up); 1: a clear coat of index u_eta_i seen
// from air (cf_ibl_coated.glsl): the coat's own lobe on top of the metal
// seen at the cosine inside the coat (Snell), transmitted in and out.
//
// Two variants of this file, one program each. Without CF_SPLIT_SUM every
// lobe is a mirror: its albedo is its Fresnel (the band's; the exact
// dielectric for the coat) and it sees the environment itself. With
// CF_SPLIT_SUM 1 (static/preview.js uses it whenever a lobe is rough) the
// lobes are lit by the split sum (Karis 2013): each albedo from a table
// over NdotV integrated once per change of the settings (albedo_table.frag
// from the LUT of cf_ibl.glsl, reference_albedo.frag from the reference
// texture), times the environment prefiltered at the lobe's roughness
// (cf_prefiltered_environment.glsl). The mirror program runs no split-sum
// code: a software rasteriser (SwiftShader) pays for every branch.
//
// The model band draws whichever model kind cf_preview_model.glsl is: the
// include generated from the kind's registry entry (fitting.models.kinds,
// preview_shaders.kinds), which GET /api/v1/domain serves with each kind
// (static/kinds.js gives it to the loader, one program per kind). A kind
// without the split-sum lookup takes its table row from
// model_albedo_table.frag (static/splitsum.js).
#ifndef CF_SPLIT_SUM
#define CF_SPLIT_SUM 0
#endif
#include "cf_preview_model.glsl"
#include "cf_fresnel_baselines.glsl"
#include "cf_environment.glsl"
#include "cf_microfacet.glsl"
#include "cf_ibl.glsl"
#include "cf_ibl_coated.glsl"
#include "cf_prefiltered_environment.glsl"
#include "cf_reference_texture.glsl"
#include "cf_reference_albedo.glsl"
#include "cf_display.glsl"

const int CF_PANEL_MODEL = 0;
const int CF_PANEL_LAZANYI = 1;
const int CF_PANEL_REFERENCE = 2;

const int CF_OUTPUT_DISPLAY = 0;     // sRGB-encoded, exposed (the canvas)
const int CF_OUTPUT_LINEAR = 1;      // exposed radiance, linear ACEScg
const int CF_OUTPUT_FRESNEL = 2;     // the metal's albedo (its Fresnel for a mirror), linear ACEScg
const int CF_OUTPUT_GEOMETRY = 3;    // (NdotV, 1 on the sphere, panel, 1)
const int CF_OUTPUT_BASE_LIGHT = 4;  // the lighting of the metal's lobe
const int CF_OUTPUT_COAT_LIGHT = 5;  // the lighting of the coat's lobe
const int CF_OUTPUT_COAT = 6;        // (coat albedo, transmission in and out, cos inside the coat, 1)

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
uniform float u_roughness;    // the metal's GGX perceptual roughness, [0, 1]
uniform int u_coated;         // 0 immersed, 1 a clear coat seen from air
uniform float u_coat_roughness; // the coat's, [0, 1]

uniform uint cf_words[14];      // the model's float16 coefficients, two per word, zero-padded
uniform vec2 cf_eta_i_range;
uniform vec3 cf_F0_air;
uniform vec3 cf_F82_air;
uniform sampler2D u_reference;
uniform vec2 u_reference_eta_i_range;
#if CF_SPLIT_SUM
uniform sampler2D u_albedo;           // albedo_table.frag: rows model, Lazanyi, coat
uniform sampler2D u_reference_albedo; // reference_albedo.frag
uniform sampler2DArray u_prefiltered; // u_environment prefiltered per roughness
#endif

layout(location = 0) out vec4 out_colour;

vec3 cf_panel_fresnel(int kind, float NdotV)
{
    if (kind == CF_PANEL_LAZANYI)
        return cf_lazanyi_adjusted(NdotV, u_eta_i, cf_F0_air, cf_F82_air);
    if (kind == CF_PANEL_REFERENCE)
        return cf_reference_lookup(u_reference, NdotV, u_eta_i, u_reference_eta_i_range);
    return cf_preview_model(NdotV, u_eta_i, cf_eta_i_range, cf_words);
}

#if CF_SPLIT_SUM
// The directional albedo of a band's metal lobe at NdotV (inside the
// coat's medium), from its table.
vec3 cf_panel_albedo(int kind, float NdotV)
{
    if (kind == CF_PANEL_REFERENCE)
        return cf_albedo_table_lookup(u_reference_albedo, 0, NdotV);
    return cf_albedo_table_lookup(u_albedo, kind == CF_PANEL_LAZANYI ? 1 : 0, NdotV);
}
#endif

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
    vec3 base_light = vec3(0.0);
    vec3 coat_light = vec3(0.0);
    vec4 coat = vec4(0.0, 1.0, 0.0, 1.0);
    float NdotV = 0.0;
    float hit = 0.0;
    if (disc > 0.0)
    {
        vec3 N = normalize(eye + (-b - sqrt(disc)) * dir);
        NdotV = cf_saturate(dot(N, -dir));
        vec3 R = reflect(dir, N);
        // The metal is seen at the cosine inside the coat when there is one.
        float mu = u_coated == 0 ? NdotV : cf_cos_in_coat(NdotV, u_eta_i);
#if CF_SPLIT_SUM
        F = cf_panel_albedo(kind, mu);
        vec3 mirror = cf_environment(u_environment, R);
        vec2 uv = cf_equirect_uv(R);
        base_light = cf_prefiltered_lighting(u_prefiltered, mirror, uv, u_roughness);
        float E_coat = cf_albedo_table_lookup(u_albedo, 2, NdotV).r;
        coat_light = cf_prefiltered_lighting(u_prefiltered, mirror, uv, u_coat_roughness);
#else
        F = cf_panel_fresnel(kind, mu);
        base_light = cf_environment(u_environment, R);
        float E_coat = cf_fresnel_dielectric(NdotV, max(u_eta_i, 1.0));
        coat_light = base_light;
#endif
        if (u_coated == 0)
            radiance = F * base_light;
        else
        {
            coat = vec4(E_coat, cf_coat_transmission(NdotV, u_eta_i), mu, 1.0);
            radiance = E_coat * coat_light + coat.y * F * base_light;
        }
        hit = 1.0;
    }
    else
        radiance = cf_environment(u_environment, dir);
    radiance *= exp2(u_exposure);

    if (u_output == CF_OUTPUT_LINEAR)
        out_colour = vec4(radiance, 1.0);
    else if (u_output == CF_OUTPUT_FRESNEL)
        out_colour = vec4(F, 1.0);
    else if (u_output == CF_OUTPUT_GEOMETRY)
        out_colour = vec4(NdotV, hit, float(panel), 1.0);
    else if (u_output == CF_OUTPUT_BASE_LIGHT)
        out_colour = vec4(base_light, 1.0);
    else if (u_output == CF_OUTPUT_COAT_LIGHT)
        out_colour = vec4(coat_light, 1.0);
    else if (u_output == CF_OUTPUT_COAT)
        out_colour = coat;
    else
        out_colour = vec4(cf_display(radiance), 1.0);
}
