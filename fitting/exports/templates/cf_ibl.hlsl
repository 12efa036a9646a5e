// Split-sum pre-integration of the coated-conductor model for image-based
// lighting: the HLSL twin of preview_shaders/glsl/cf_ibl.glsl (and of
// fitting/shading/ibl.py). The LUT (GET /api/v1/ibl-lut, docs/shading.md)
// is a Texture3D of float (A, B, G): texel (i, j, k) at NdotV = (i/(W-1))^2,
// roughness j/(H-1), slice k evenly spaced in log(alpha + 1) over
// alpha_range. Read with Load and interpolated here in float32.
// References: Karis 2013 (split sum); Kulla & Conty 2017 (average Fresnel);
// Vernooij 2024, Eq. 1 (the model).

static const float CF_IBL_G_FLOOR = 1.0e-30;

float3 cf_ibl_slice(Texture3D<float4> lut, int3 size, float2 xy, int k)
{
    int2 i0 = clamp(int2(floor(xy)), int2(0, 0), size.xy - 2);
    float2 f = xy - float2(i0);
    float3 t00 = lut.Load(int4(i0, k, 0)).rgb;
    float3 t10 = lut.Load(int4(i0 + int2(1, 0), k, 0)).rgb;
    float3 t01 = lut.Load(int4(i0 + int2(0, 1), k, 0)).rgb;
    float3 t11 = lut.Load(int4(i0 + int2(1, 1), k, 0)).rgb;
    return (1.0 - f.y) * ((1.0 - f.x) * t00 + f.x * t10) + f.y * ((1.0 - f.x) * t01 + f.x * t11);
}

// (A, B, G(alpha)) at NdotV, roughness, alpha: bilinear on the two slices
// around alpha, geometric between them with t linear in alpha.
float3 cf_ibl_terms(Texture3D<float4> lut, float2 alpha_range, float NdotV, float roughness, float alpha)
{
    uint w, h, d;
    lut.GetDimensions(w, h, d);
    int3 size = int3(w, h, d);
    float2 xy = float2(sqrt(saturate(NdotV)), saturate(roughness)) * float2(size.xy - 1);
    float2 s_range = log(alpha_range + 1.0);
    float a = clamp(alpha, alpha_range.x, alpha_range.y);
    float z = (log(a + 1.0) - s_range.x) / (s_range.y - s_range.x) * float(size.z - 1);
    int k = clamp(int(floor(z)), 0, size.z - 2);
    float step_ = (s_range.y - s_range.x) / float(size.z - 1);
    float alpha_k = exp(s_range.x + float(k) * step_) - 1.0;
    float alpha_k1 = exp(s_range.x + float(k + 1) * step_) - 1.0;
    float t = clamp((a - alpha_k) / (alpha_k1 - alpha_k), 0.0, 1.0);
    float3 low = cf_ibl_slice(lut, size, xy, k);
    float3 high = cf_ibl_slice(lut, size, xy, k + 1);
    float G = exp2((1.0 - t) * log2(max(low.z, CF_IBL_G_FLOOR)) + t * log2(max(high.z, CF_IBL_G_FLOOR)));
    return float3(low.xy, G);
}

// Directional albedo of the GGX BRDF with the model's Fresnel:
// F0 A + B - a G(alpha) per channel; multiply by the environment
// prefiltered at the roughness.
float3 cf_split_sum_model(Texture3D<float4> lut, float2 alpha_range, float NdotV, float roughness,
                          float3 F0, float3 a, float3 alpha)
{
    float3 tR = cf_ibl_terms(lut, alpha_range, NdotV, roughness, alpha.r);
    float G_g = cf_ibl_terms(lut, alpha_range, NdotV, roughness, alpha.g).z;
    float G_b = cf_ibl_terms(lut, alpha_range, NdotV, roughness, alpha.b).z;
    return F0 * tR.x + tR.y - a * float3(tR.z, G_g, G_b);
}

// Schlick's Fresnel pre-integrated: F0 A + B (Karis 2013).
float3 cf_split_sum_schlick(Texture3D<float4> lut, float2 alpha_range, float NdotV, float roughness, float3 F0)
{
    float3 t = cf_ibl_terms(lut, alpha_range, NdotV, roughness, alpha_range.x);
    return F0 * t.x + t.y;
}

// Adjusted Lazanyi pre-integrated: the model's form with alpha = 6.
float3 cf_split_sum_lazanyi(Texture3D<float4> lut, float2 alpha_range, float NdotV, float roughness,
                            float3 F0, float3 a)
{
    float3 t = cf_ibl_terms(lut, alpha_range, NdotV, roughness, 6.0);
    return F0 * t.x + t.y - a * t.z;
}

// Kulla & Conty 2017: the closed-form average 2 int F mu dmu of the model.
float3 cf_average_fresnel(float3 F0, float3 a, float3 alpha)
{
    float3 al = max(alpha, CF_ALPHA_MIN);
    return F0 + (1.0 - F0) / 21.0 - 4.0 * a / ((al + 1.0) * (al + 2.0) * (al + 3.0));
}
