
// ${name}: ${source}
// Fit ${fit_id} (${model}); ${quality}.
// Coefficients are the shipped float16 values; row c of each float3x3 holds
// channel c's powers (1, t, t^2).
static const float2 ${prefix}_ETA_I_RANGE = float2(${eta_lo}, ${eta_hi});
static const float3x3 ${prefix}_F0 = float3x3(${F0});
static const float3x3 ${prefix}_A = float3x3(${a});
static const float3x3 ${prefix}_ALPHA = float3x3(${alpha});

float3 cf_material_${ident}(float NdotV, float eta_i)
{
    return cf_coated_conductor(NdotV, eta_i, ${prefix}_ETA_I_RANGE,
                               ${prefix}_F0, ${prefix}_A, ${prefix}_ALPHA);
}
