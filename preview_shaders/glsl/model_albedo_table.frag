#version 430
// Row 0 of the preview's albedo table (albedo_table.frag's layout: texel
// (i, 0) at NdotV = (i / (n - 1))^2) for a model kind without the
// split-sum lookup: the directional albedo of the metal's GGX lobe at
// u_roughness with the kind's own Fresnel, cf_preview_model.glsl (the
// include generated from the kind's registry entry), by the quadrature of
// cf_reference_albedo.glsl (Hammersley points through visible-normal
// sampling, as cf_rgb_conductor_albedo.glsl); at roughness 0 a mirror, its
// Fresnel. static/splitsum.js draws it over albedo_table.frag's row 0.
//
// References: Karis 2013 (split sum); Heitz 2018 (visible normals).
#include "cf_common.glsl"
#include "cf_microfacet.glsl"
#include "cf_preview_model.glsl"

uniform vec2 u_resolution;
uniform float u_eta_i;
uniform float u_roughness;
uniform uint cf_words[14];
uniform vec2 cf_eta_i_range;
uniform int u_samples;

layout(location = 0) out vec4 out_albedo;

// E(mu) = (1/n) sum_i F(v.h_i) G2(v, l_i) / G1(v), F the kind's Fresnel.
vec3 cf_model_albedo(float NdotV, float roughness, int samples)
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
        if (NdotL > 0.0)
            sum += cf_smith_G2(mu, NdotL, alpha_g) / G1 * cf_preview_model(VdotH, u_eta_i, cf_eta_i_range, cf_words);
    }
    return sum / float(max(samples, 1));
}

void main()
{
    float s = floor(gl_FragCoord.x) / max(u_resolution.x - 1.0, 1.0);
    float mu = s * s;
    vec3 E = u_roughness <= 0.0
        ? cf_preview_model(mu, u_eta_i, cf_eta_i_range, cf_words)
        : cf_model_albedo(mu, u_roughness, u_samples);
    out_albedo = vec4(E, 1.0);
}
