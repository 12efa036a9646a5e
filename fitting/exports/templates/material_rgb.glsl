
// ${name}: ${source}
// Fit ${fit_id} (${model}); ${quality}.
// n and k per channel (R, G, B) are the shipped float16 values.
const vec3 ${prefix}_N = vec3(${n});
const vec3 ${prefix}_K = vec3(${k});

vec3 cf_material_${ident}(float NdotV, float eta_i)
{
    return cf_rgb_conductor(NdotV, eta_i, ${prefix}_N, ${prefix}_K);
}
