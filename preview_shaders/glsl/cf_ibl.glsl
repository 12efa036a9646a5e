// Split-sum pre-integration of the coated-conductor model for image-based
// lighting: the GLSL mirror of fitting/shading/ibl.py. The LUT
// (docs/shading.md) is a 3D float texture, texel (i, j, k) = (A, B, G) at
// NdotV = (i / (W - 1))^2, roughness j / (H - 1) and slice k, the slices
// evenly spaced in log(alpha + 1) over alpha_range. Fetched with texelFetch
// and interpolated here in float32: hardware filtering rounds its weights
// to 8 bits on most GPUs, too coarse for 1e-5.
//
// References: Karis 2013 (split sum, SIGGRAPH course); Kulla & Conty 2017
// (average Fresnel); Vernooij 2024, Eq. 1 (the model).
#ifndef CF_IBL_GLSL
#define CF_IBL_GLSL

#include "cf_common.glsl"

// GLSL ES 3.00 gives sampler3D no default precision (the pack downloads are
// checked against ES 3.00 and GLSL 3.30).
#ifdef GL_ES
precision highp sampler3D;
#endif

// As fitting.shading.ibl._G_FLOOR: keeps log2(G) finite where G = 0
// (NdotV = 0), above FLT_MIN.
const float CF_IBL_G_FLOOR = 1.0e-30;

// Bilinear (A, B, G) of slice k at continuous texel coordinates xy.
vec3 cf_ibl_slice(sampler3D lut, ivec3 size, vec2 xy, int k)
{
    // Lower corner kept inside [0, size - 2] so the upper one exists; the
    // fraction may then reach 1 at the last node, which is exact.
    ivec2 i0 = clamp(ivec2(floor(xy)), ivec2(0), size.xy - 2);
    vec2 f = xy - vec2(i0);
    vec3 t00 = texelFetch(lut, ivec3(i0, k), 0).rgb;
    vec3 t10 = texelFetch(lut, ivec3(i0 + ivec2(1, 0), k), 0).rgb;
    vec3 t01 = texelFetch(lut, ivec3(i0 + ivec2(0, 1), k), 0).rgb;
    vec3 t11 = texelFetch(lut, ivec3(i0 + ivec2(1, 1), k), 0).rgb;
    return (1.0 - f.y) * ((1.0 - f.x) * t00 + f.x * t10) + f.y * ((1.0 - f.x) * t01 + f.x * t11);
}

// Karis 2013 split sum with the model's third term: (A, B, G(alpha)) at
// NdotV, roughness, alpha (fitting.shading.ibl.SplitSumLUT.lookup):
// bilinear on the two slices around alpha, geometric between them with t
// linear in alpha (G of a mirror lobe is exactly exponential in alpha).
vec3 cf_ibl_terms(sampler3D lut, vec2 alpha_range, float NdotV, float roughness, float alpha)
{
    ivec3 size = textureSize(lut, 0);
    vec2 xy = vec2(sqrt(cf_saturate(NdotV)), cf_saturate(roughness)) * vec2(size.xy - 1);
    vec2 s_range = log(alpha_range + 1.0);
    float a = clamp(alpha, alpha_range.x, alpha_range.y);
    float z = (log(a + 1.0) - s_range.x) / (s_range.y - s_range.x) * float(size.z - 1);
    int k = clamp(int(floor(z)), 0, size.z - 2);
    float step = (s_range.y - s_range.x) / float(size.z - 1);
    float alpha_k = exp(s_range.x + float(k) * step) - 1.0;
    float alpha_k1 = exp(s_range.x + float(k + 1) * step) - 1.0;
    float t = clamp((a - alpha_k) / (alpha_k1 - alpha_k), 0.0, 1.0);
    vec3 low = cf_ibl_slice(lut, size, xy, k);
    vec3 high = cf_ibl_slice(lut, size, xy, k + 1);
    float G = exp2((1.0 - t) * log2(max(low.z, CF_IBL_G_FLOOR)) + t * log2(max(high.z, CF_IBL_G_FLOOR)));
    return vec3(low.xy, G);
}

// Directional albedo of the GGX BRDF with the model's Fresnel (Vernooij
// 2024, Eq. 1 integrated term by term): F0 A + B - a G(alpha) per channel;
// multiply by the environment prefiltered at the roughness
// (fitting.shading.ibl.split_sum_model).
vec3 cf_split_sum_model(sampler3D lut, vec2 alpha_range, float NdotV, float roughness,
                        vec3 F0, vec3 a, vec3 alpha)
{
    vec3 tR = cf_ibl_terms(lut, alpha_range, NdotV, roughness, alpha.r);
    float G_g = cf_ibl_terms(lut, alpha_range, NdotV, roughness, alpha.g).z;
    float G_b = cf_ibl_terms(lut, alpha_range, NdotV, roughness, alpha.b).z;
    return F0 * tR.x + tR.y - a * vec3(tR.z, G_g, G_b);
}

// Schlick's Fresnel pre-integrated: F0 A + B (Karis 2013).
vec3 cf_split_sum_schlick(sampler3D lut, vec2 alpha_range, float NdotV, float roughness, vec3 F0)
{
    vec3 t = cf_ibl_terms(lut, alpha_range, NdotV, roughness, alpha_range.x);
    return F0 * t.x + t.y;
}

// Adjusted Lazanyi (Hoffman 2019) pre-integrated: the model's form with
// alpha = 6; F0 is the external-medium F0 and a from F0, F82 in air, both
// from the CPU (cf_f0_in_medium, cf_lazanyi_a).
vec3 cf_split_sum_lazanyi(sampler3D lut, vec2 alpha_range, float NdotV, float roughness,
                          vec3 F0, vec3 a)
{
    vec3 t = cf_ibl_terms(lut, alpha_range, NdotV, roughness, 6.0);
    return F0 * t.x + t.y - a * t.z;
}

// Kulla & Conty 2017, Eq. 15 (Fdez-Aguera 2019): the closed-form average
// 2 int F mu dmu of the model, F0 + (1 - F0)/21 - 4a / ((alpha+1)(alpha+2)(alpha+3))
// (fitting.shading.ibl.average_fresnel).
vec3 cf_average_fresnel(vec3 F0, vec3 a, vec3 alpha)
{
    vec3 al = max(alpha, vec3(CF_ALPHA_MIN));
    return F0 + (1.0 - F0) / 21.0 - 4.0 * a / ((al + 1.0) * (al + 2.0) * (al + 3.0));
}

#endif
