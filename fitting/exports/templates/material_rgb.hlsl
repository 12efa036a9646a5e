
// ${name}: ${source}
// Fit ${fit_id} (${model}); ${quality}.
// n and k per channel (R, G, B) are the shipped float16 values.
static const float3 ${prefix}_N = float3(${n});
static const float3 ${prefix}_K = float3(${k});

float3 cf_material_${ident}(float NdotV, float eta_i)
{
    return cf_rgb_conductor(NdotV, eta_i, ${prefix}_N, ${prefix}_K);
}
