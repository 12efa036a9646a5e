// The Fresnel terms the coated-conductor model is compared with: Schlick,
// adjusted Lazanyi (Hoffman's F82 form with the external-medium F0
// adjustment) and the exact RGB conductor Fresnel equations.
#ifndef CF_FRESNEL_BASELINES_GLSL
#define CF_FRESNEL_BASELINES_GLSL

#include "cf_common.glsl"

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
    // fitting.baselines (n stays finite, F0' -> 1).
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

// Principal square root of complex z = re + i im per channel; the branch
// that needs no cancellation is taken first (Kahan's formulation).
void cf_complex_sqrt(vec3 re, vec3 im, out vec3 root_re, out vec3 root_im)
{
    vec3 modulus = sqrt(re * re + im * im);
    vec3 t = sqrt(0.5 * (modulus + abs(re)));
    // t is 0 only for z = 0; the floor avoids 0/0 there.
    vec3 u = 0.5 * im / max(t, vec3(CF_FLT_MIN));
    bvec3 right = greaterThanEqual(re, vec3(0.0));
    root_re = mix(abs(u), t, vec3(right));
    // Left half-plane: the root's imaginary part takes the sign of im (+ on
    // the cut, the principal branch).
    vec3 signed_t = mix(-t, t, vec3(greaterThanEqual(im, vec3(0.0))));
    root_im = mix(signed_t, u, vec3(right));
}

// Exact unpolarised Fresnel reflectance of a conductor n + i k seen from a
// dielectric of index eta_i, RGB-wise (Born & Wolf 1999, Section 1.5; pbrt-v4
// FrComplex); the GLSL mirror of fitting.fresnel.fresnel_conductor.
vec3 cf_fresnel_conductor(float NdotV, float eta_i, vec3 n, vec3 k)
{
    float mu = cf_saturate(NdotV);
    // Relative index eta = (n + i k) / eta_i.
    vec3 er = n / eta_i;
    vec3 ei = k / eta_i;
    // sin^2 theta_t = (1 - mu^2) / eta^2.
    vec3 eta2_re = er * er - ei * ei;
    vec3 eta2_im = 2.0 * er * ei;
    vec3 eta2_abs2 = max(eta2_re * eta2_re + eta2_im * eta2_im, vec3(CF_FLT_MIN));
    float sin2_i = 1.0 - mu * mu;
    vec3 sin2_re = sin2_i * eta2_re / eta2_abs2;
    vec3 sin2_im = -sin2_i * eta2_im / eta2_abs2;
    // cos theta_t on the principal branch: for k = 0 past the critical angle
    // it is imaginary and |r_s| = |r_p| = 1 (total internal reflection).
    vec3 ct_re, ct_im;
    cf_complex_sqrt(1.0 - sin2_re, -sin2_im, ct_re, ct_im);
    // eta cos theta_t
    vec3 ect_re = er * ct_re - ei * ct_im;
    vec3 ect_im = er * ct_im + ei * ct_re;
    // r_s = (mu - eta cos_t) / (mu + eta cos_t)
    vec3 ns2 = (mu - ect_re) * (mu - ect_re) + ect_im * ect_im;
    vec3 ds2 = (mu + ect_re) * (mu + ect_re) + ect_im * ect_im;
    // r_p = (eta mu - cos_t) / (eta mu + cos_t)
    vec3 np2 = (er * mu - ct_re) * (er * mu - ct_re) + (ei * mu - ct_im) * (ei * mu - ct_im);
    vec3 dp2 = (er * mu + ct_re) * (er * mu + ct_re) + (ei * mu + ct_im) * (ei * mu + ct_im);
    // Both denominators vanish only for mu = 0 at an index-matched interface,
    // where there is no interface and R is 0.
    vec3 R = 0.5 * (ns2 / max(ds2, vec3(CF_FLT_MIN)) + np2 / max(dp2, vec3(CF_FLT_MIN)));
    return clamp(R, 0.0, 1.0);
}

#endif
