// The Fresnel terms the coated-conductor model is compared with: Schlick,
// adjusted Lazanyi (Hoffman's F82 form with the external-medium F0
// adjustment) and, from cf_rgb_conductor.glsl, the exact RGB conductor
// Fresnel equations (cf_fresnel_conductor).
#ifndef CF_FRESNEL_BASELINES_GLSL
#define CF_FRESNEL_BASELINES_GLSL

#include "cf_common.glsl"
#include "cf_rgb_conductor.glsl"

// Schlick 1994, Eq. 24: F = F0 + (1 - F0)(1 - mu)^5.
vec3 cf_schlick(float NdotV, vec3 F0)
{
    float x = 1.0 - cf_saturate(NdotV);
    return F0 + (1.0 - F0) * cf_pow5(x);
}

// Hoffman 2020 ("Some thoughts on the Fresnel term", SIGGRAPH course):
// F0 of a surface seen from a medium of index eta_i, through the real index
// n = (1 + sqrt F0) / (1 - sqrt F0) that gives the air F0.
vec3 cf_f0_in_medium(vec3 F0_air, float eta_i)
{
    // sqrt(F0) -> 1 sends n to infinity: F0 is kept below 1 - 1e-6, as in
    // fitting.models.baselines (n stays finite, F0' -> 1).
    vec3 s = sqrt(clamp(F0_air, 0.0, 1.0 - 1.0e-6));
    vec3 n = (1.0 + s) / (1.0 - s);
    vec3 r = (n - eta_i) / (n + eta_i);
    return r * r;
}

// Lazanyi & Szirmay-Kalos 2005 error term in Hoffman's 2019 F82 notation:
// F = F0 + (1 - F0)(1 - mu)^5 - a mu (1 - mu)^6. With eta_i constant over a
// scene, F0 (cf_f0_in_medium) and a (cf_lazanyi_a) are computed once on the
// CPU and this is all the shader evaluates (the counterpart of the
// scene-specialised model).
vec3 cf_lazanyi(float NdotV, vec3 F0, vec3 a)
{
    float mu = cf_saturate(NdotV);
    float x = 1.0 - mu;
    float x5 = cf_pow5(x);
    return F0 + (1.0 - F0) * x5 - a * (mu * x5 * x);
}

// Hoffman 2019: a = [F0 + (1 - F0)(1 - mu_bar)^5 - F82] / (mu_bar (1 - mu_bar)^6)
// from the air F0 and F82, mu_bar = 1/7 (cos 81.7 deg).
vec3 cf_lazanyi_a(vec3 F0_air, vec3 F82_air)
{
    const float mu_bar = 1.0 / 7.0;
    const float x_bar = 1.0 - mu_bar;
    const float x_bar5 = x_bar * x_bar * x_bar * x_bar * x_bar;
    const float denominator = mu_bar * x_bar5 * x_bar;
    return (F0_air + (1.0 - F0_air) * x_bar5 - F82_air) / denominator;
}

// The paper's "adjusted Lazanyi": cf_lazanyi with a from the air F0 and F82
// and the Hoffman 2020 external-medium F0 at eta_i, both in the shader (what
// a renderer computes when eta_i varies per pixel).
vec3 cf_lazanyi_adjusted(float NdotV, float eta_i, vec3 F0_air, vec3 F82_air)
{
    return cf_lazanyi(NdotV, cf_f0_in_medium(F0_air, eta_i), cf_lazanyi_a(F0_air, F82_air));
}

// Adjusted Lazanyi with its per-material constants from the CPU, as a
// renderer with eta_i varying per pixel computes it: the equivalent real
// index n of the air F0 (fitting.models.baselines.equivalent_index) and a
// (cf_lazanyi_a) are uniforms, and only the external-medium F0
// ((n - eta_i) / (n + eta_i))^2 is evaluated per pixel.
vec3 cf_lazanyi_adjusted_lean(float NdotV, float eta_i, vec3 n, vec3 a)
{
    vec3 r = (n - eta_i) / (n + eta_i);
    return cf_lazanyi(NdotV, r * r, a);
}

#endif
