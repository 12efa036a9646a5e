
// ${name}: ${source}
// Fit ${fit_id} (${model}); ${quality}.
// Coefficients are the shipped float16 values; column c of each mat3 holds
// channel c's powers (1, t, t^2).
const vec2 ${prefix}_ETA_I_RANGE = vec2(${eta_lo}, ${eta_hi});
const mat3 ${prefix}_F0 = mat3(${F0});
const mat3 ${prefix}_A = mat3(${a});
const mat3 ${prefix}_ALPHA = mat3(${alpha});

vec3 cf_material_${ident}(float NdotV, float eta_i)
{
    return cf_coated_conductor(NdotV, eta_i, ${prefix}_ETA_I_RANGE,
                               ${prefix}_F0, ${prefix}_A, ${prefix}_ALPHA);
}
