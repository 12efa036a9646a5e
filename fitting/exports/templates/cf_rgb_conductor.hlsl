// The rgb-conductor model kind: the exact Fresnel equations of a conductor
// per RGB channel with one complex index n + i k per channel, seen from a
// coating of index eta_i (the relative index (n + i k) / eta_i). The HLSL
// mirror of fitting/models/rgb_conductor.py and
// preview_shaders/glsl/cf_rgb_conductor.glsl (Born & Wolf 1999, Section 1.5;
// pbrt-v4 FrComplex).
#ifndef CF_RGB_CONDUCTOR_HLSL
#define CF_RGB_CONDUCTOR_HLSL

// Smallest normal float32: denominators are kept above it so a degenerate
// interface gives the physical limit instead of NaN.
static const float CF_RGB_FLT_MIN = 1.17549435e-38;

// Principal square root of complex z = re + i im per channel; the branch
// that needs no cancellation is taken first (Kahan's formulation).
void cf_complex_sqrt(float3 re, float3 im, out float3 root_re, out float3 root_im)
{
    float3 modulus = sqrt(re * re + im * im);
    float3 t = sqrt(0.5 * (modulus + abs(re)));
    // t is 0 only for z = 0; the floor avoids 0/0 there.
    float3 u = 0.5 * im / max(t, CF_RGB_FLT_MIN);
    float3 right = step(0.0, re);
    root_re = lerp(abs(u), t, right);
    // Left half-plane: the root's imaginary part takes the sign of im.
    float3 signed_t = lerp(-t, t, step(0.0, im));
    root_im = lerp(signed_t, u, right);
}

// Exact unpolarised Fresnel reflectance of n + i k seen from eta_i, RGB-wise.
float3 cf_rgb_conductor(float NdotV, float eta_i, float3 n, float3 k)
{
    float mu = saturate(NdotV);
    float3 er = n / eta_i;
    float3 ei = k / eta_i;
    // sin^2 theta_t = (1 - mu^2) / eta^2.
    float3 eta2_re = er * er - ei * ei;
    float3 eta2_im = 2.0 * er * ei;
    float3 eta2_abs2 = max(eta2_re * eta2_re + eta2_im * eta2_im, CF_RGB_FLT_MIN);
    float sin2_i = 1.0 - mu * mu;
    float3 sin2_re = sin2_i * eta2_re / eta2_abs2;
    float3 sin2_im = -sin2_i * eta2_im / eta2_abs2;
    // cos theta_t on the principal branch: for k = 0 past the critical angle
    // it is imaginary and |r_s| = |r_p| = 1 (total internal reflection).
    float3 ct_re, ct_im;
    cf_complex_sqrt(1.0 - sin2_re, -sin2_im, ct_re, ct_im);
    float3 ect_re = er * ct_re - ei * ct_im;
    float3 ect_im = er * ct_im + ei * ct_re;
    float3 ns2 = (mu - ect_re) * (mu - ect_re) + ect_im * ect_im;
    float3 ds2 = (mu + ect_re) * (mu + ect_re) + ect_im * ect_im;
    float3 np2 = (er * mu - ct_re) * (er * mu - ct_re) + (ei * mu - ct_im) * (ei * mu - ct_im);
    float3 dp2 = (er * mu + ct_re) * (er * mu + ct_re) + (ei * mu + ct_im) * (ei * mu + ct_im);
    // Both denominators vanish only for mu = 0 at an index-matched interface,
    // where there is no interface and R is 0.
    float3 R = 0.5 * (ns2 / max(ds2, CF_RGB_FLT_MIN) + np2 / max(dp2, CF_RGB_FLT_MIN));
    return saturate(R);
}

#endif
