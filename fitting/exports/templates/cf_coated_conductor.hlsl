// The coated-conductor Fresnel model of Vernooij (2024), Eq. 1 and 2: the
// HLSL mirror of fitting/models/coated_conductor.py and preview_shaders/glsl/cf_coated_conductor.glsl.
#ifndef CF_COATED_CONDUCTOR_HLSL
#define CF_COATED_CONDUCTOR_HLSL

// Lower clamp of the exponent alpha, as fitting.models.coated_conductor.ALPHA_MIN: keeps
// (1 - mu)^alpha finite at mu = 1 (pow(0, y) is undefined for y <= 0).
static const float CF_ALPHA_MIN = 1.0e-3;

// t = (eta_i - lo) / (hi - lo) clamped to [0, 1]; a single-index fit
// (hi == lo) has t = 0 (fitting.models.coated_conductor.normalised_eta_i).
float cf_normalised_eta_i(float eta_i, float2 eta_i_range)
{
    float width = eta_i_range.y - eta_i_range.x;
    if (width <= 0.0)
        return 0.0;
    return saturate((eta_i - eta_i_range.x) / width);
}

// Vernooij 2024, Eq. 1 and 2 (in t): each parameter matrix has channel c's
// powers (1, t, t^2) in row c, so mul(M, T) gives the three channels.
float3 cf_coated_conductor(float NdotV, float eta_i, float2 eta_i_range,
                           float3x3 C_F0, float3x3 C_a, float3x3 C_alpha)
{
    float t = cf_normalised_eta_i(eta_i, eta_i_range);
    float3 T = float3(1.0, t, t * t);
    float3 F0 = mul(C_F0, T);
    float3 a = mul(C_a, T);
    // alpha >= CF_ALPHA_MIN > 0, so pow(0, alpha) = 0 is defined at mu = 1.
    float3 alpha = max(mul(C_alpha, T), CF_ALPHA_MIN);
    // mu from an interpolated normal can leave [0, 1] by rounding.
    float mu = saturate(NdotV);
    float x = 1.0 - mu;
    float x2 = x * x;
    float x5 = x2 * x2 * x;
    return F0 + (1.0 - F0) * x5 - a * mu * pow(float3(x, x, x), alpha);
}

#endif
