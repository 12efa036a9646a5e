// The split sum of the coated mode, by parts so that each lobe takes its
// own prefiltered lighting (fitting.shading.ibl.split_sum_coated):
//     E = E_c(mu) + [1 - F_c(mu)]^2 E_s(mu_t),
// the coat's lobe E_c, the base's albedo E_s at the cosine inside the coat
// mu_t (Snell through the coat's mean surface), transmitted in and out.
//
// References: Karis 2013 (split sum); Weidlich & Wilkie 2007 (layering, as
// the OpenPBR Surface coat describes it); Born & Wolf 1999 (Snell, Fresnel).
#ifndef CF_IBL_COATED_GLSL
#define CF_IBL_COATED_GLSL

#include "cf_common.glsl"
#include "cf_ibl.glsl"
#include "cf_microfacet.glsl"

// mu_t = sqrt(1 - (1 - mu^2) / eta_i^2): the cosine inside a coat of index
// eta_i >= 1 of a direction at cosine mu in air (cf_refract_into_coat's z).
float cf_cos_in_coat(float NdotV, float eta_i)
{
    float eta = max(eta_i, 1.0);
    float mu = cf_saturate(NdotV);
    // eta >= 1 keeps the argument in [1 - 1/eta^2, 1]; the max absorbs rounding.
    return sqrt(max(1.0 - (1.0 - mu * mu) / (eta * eta), 0.0));
}

// [1 - F_c(mu)]^2: the coat's transmission in and out at the view angle
// (the light leaves at the mirror angle, so both crossings share mu).
float cf_coat_transmission(float NdotV, float eta_i)
{
    float T = 1.0 - cf_fresnel_dielectric(NdotV, max(eta_i, 1.0));
    return T * T;
}

// The coat's own lobe: Schlick's form at the coat's F0 = ((eta - 1) /
// (eta + 1))^2 pre-integrated at coat_roughness; 0 at eta_i = 1, where
// there is no interface (Schlick's B term is not 0 there).
float cf_split_sum_coat(sampler3D lut, vec2 alpha_range, float NdotV, float coat_roughness,
                        float eta_i)
{
    float eta = max(eta_i, 1.0);
    float F0c = (eta - 1.0) / (eta + 1.0);
    F0c *= F0c;
    return eta > 1.0 ? cf_split_sum_schlick(lut, alpha_range, NdotV, coat_roughness, vec3(F0c)).r : 0.0;
}

#endif
