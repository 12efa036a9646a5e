// Directional albedos of the editor's split-sum preview: the GGX lobe with
// the spectral reference texture (cf_reference_texture.glsl) as its
// Fresnel, a Fresnel that is a table rather than the model's form (whose
// albedo the LUT of cf_ibl.glsl holds): the GLSL mirror of
// fitting.shading.ibl.directional_albedo with the reference texture's
// bilinear lookup as the Fresnel function; and the lookup of the albedo
// tables the preview integrates once per change of its settings.
//
// References: Karis 2013 (split sum); Heitz 2018 (visible normals).
#ifndef CF_REFERENCE_ALBEDO_GLSL
#define CF_REFERENCE_ALBEDO_GLSL

#include "cf_common.glsl"
#include "cf_microfacet.glsl"
#include "cf_reference_texture.glsl"

// E(mu) = (1/n) sum_i F(v.h_i) G2(v, l_i) / G1(v) over the n Hammersley
// points through visible-normal sampling (the LUT's quadrature,
// fitting.shading.lut._node_terms), F the reference at (v.h, eta_i).
vec3 cf_reference_albedo(sampler2D reference, float NdotV, float eta_i, vec2 eta_i_range,
                         float roughness, int samples)
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
            sum += cf_smith_G2(mu, NdotL, alpha_g) / G1
                 * cf_reference_lookup(reference, VdotH, eta_i, eta_i_range);
    }
    return sum / float(max(samples, 1));
}

// Row `row` of a table of directional albedos at NdotV nodes
// mu_i = (i / (n - 1))^2, n texels a row (albedo_table.frag and
// reference_albedo.frag write them), interpolated linearly in sqrt(mu)
// between the nodes around NdotV, as the LUT's NdotV axis (cf_ibl_terms):
// with n - 1 a multiple of the LUT's, the LUT's own nodes are among the
// table's and a table of its split sum reproduces the LUT's lookup.
vec3 cf_albedo_table_lookup(sampler2D table, int row, float NdotV)
{
    int n = textureSize(table, 0).x;
    float x = sqrt(cf_saturate(NdotV)) * float(n - 1);
    // The node below x, kept <= n - 2 so that the one above exists; the
    // fraction then reaches 1 at the last node, which is exact.
    int i = min(int(floor(x)), n - 2);
    return mix(texelFetch(table, ivec2(i, row), 0).rgb, texelFetch(table, ivec2(i + 1, row), 0).rgb,
               x - float(i));
}

#endif
