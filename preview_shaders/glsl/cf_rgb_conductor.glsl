// The rgb-conductor model kind: the exact Fresnel equations of a conductor
// per RGB channel with one complex index n + i k per channel, seen from a
// coating of index eta_i (the relative index (n + i k) / eta_i, as pbrt-v4's
// CoatedConductor). The GLSL mirror of fitting/models/rgb_conductor.py and
// fitting.optics.fresnel.fresnel_conductor.
//
// Pack layout (fitting.models.rgb_conductor): coefficients[p][c], parameter
// p in (n, k), channel c in (R, G, B); 6 float16 values in that order, two
// per uint32 (fitting.models.pack.halves_to_uint32), so 3 words.
#ifndef CF_RGB_CONDUCTOR_GLSL
#define CF_RGB_CONDUCTOR_GLSL

#include "cf_common.glsl"

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
// FrComplex); the GLSL mirror of fitting.optics.fresnel.fresnel_conductor.
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

// The rgb-conductor kind from float n, k per channel.
vec3 cf_rgb_conductor(float NdotV, float eta_i, vec3 n, vec3 k)
{
    return cf_fresnel_conductor(NdotV, eta_i, n, k);
}

// Decodes the 6 float16 values packed two per uint32, the earlier one in the
// low 16 bits, so unpackHalf2x16(w).x is the earlier half.
void cf_unpack_rgb_conductor(uint words[3], out vec3 n, out vec3 k)
{
    vec2 h0 = unpackHalf2x16(words[0]);
    vec2 h1 = unpackHalf2x16(words[1]);
    vec2 h2 = unpackHalf2x16(words[2]);
    n = vec3(h0.x, h0.y, h1.x);
    k = vec3(h1.y, h2.x, h2.y);
}

// The rgb-conductor kind from the packed halves, exactly what a renderer uploads.
vec3 cf_rgb_conductor_packed(float NdotV, float eta_i, uint words[3])
{
    vec3 n, k;
    cf_unpack_rgb_conductor(words, n, k);
    return cf_fresnel_conductor(NdotV, eta_i, n, k);
}

#endif
