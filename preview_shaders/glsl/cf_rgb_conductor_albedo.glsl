// Directional albedo of the GGX lobe with the rgb-conductor kind's exact
// Fresnel (cf_rgb_conductor.glsl), whose form the split-sum LUT of
// cf_ibl.glsl does not hold: the quadrature of cf_reference_albedo.glsl
// (fitting.shading.ibl.directional_albedo: Hammersley points through
// visible-normal sampling) with cf_fresnel_conductor as the Fresnel.
//
// References: Karis 2013 (split sum); Heitz 2018 (visible normals).
#ifndef CF_RGB_CONDUCTOR_ALBEDO_GLSL
#define CF_RGB_CONDUCTOR_ALBEDO_GLSL

#include "cf_common.glsl"
#include "cf_microfacet.glsl"
#include "cf_rgb_conductor.glsl"

// E(mu) = (1/n) sum_i F(v.h_i) G2(v, l_i) / G1(v), F the exact conductor
// (n + i k) / eta_i per channel.
vec3 cf_rgb_conductor_albedo(float NdotV, float eta_i, vec3 n, vec3 k, float roughness, int samples)
{
    // NdotV = 0: the limit from above (G1 -> 0 cancels), as numpy.
    float mu = max(cf_saturate(NdotV), 1.0e-6);
    vec3 V = vec3(sqrt(1.0 - mu * mu), 0.0, mu);
    float alpha_g = cf_alpha_g_from_roughness(roughness);
    float G1 = cf_smith_G1(mu, alpha_g);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < samples; i++)
    {
        vec3 H = cf_sample_visible_normal(V, alpha_g, cf_hammersley(i, samples));
        float VdotH = cf_saturate(dot(V, H));
        float NdotL = 2.0 * VdotH * H.z - V.z;
        // A light below the surface scores 0 (cf_smith_G2 is 0 there too).
        if (NdotL > 0.0)
            sum += cf_smith_G2(mu, NdotL, alpha_g) / G1 * cf_fresnel_conductor(VdotH, eta_i, n, k);
    }
    return sum / float(max(samples, 1));
}

#endif
