// The GGX microfacet BRDF with the coated-conductor model's Fresnel: the
// GLSL mirror of fitting/shading/microfacet.py, function by function.
// Directions are unit vectors in the shading frame (normal +z) pointing away
// from the surface; V the view, L the light, H their half vector.
//
// References: Walter et al. 2007 (GGX, EGSR); Heitz 2014 (Smith
// masking-shadowing, JCGT 3(2)); Heitz 2018 (sampling the visible normals,
// JCGT 7(4)); Weidlich & Wilkie 2007 (layered microfacet
// surfaces, GRAPHITE) as the OpenPBR Surface coat describes it; Vernooij
// 2024 (the model, Eurographics).
#ifndef CF_MICROFACET_GLSL
#define CF_MICROFACET_GLSL

#include "cf_common.glsl"
#include "cf_coated_conductor.glsl"

const float CF_PI = 3.14159265358979;

// As fitting.shading.microfacet.ROUGHNESS_MIN: r = 0 is a Dirac lobe; at
// alpha_g = 4e-4 the GGX peak (2e6) is well inside float32.
const float CF_ROUGHNESS_MIN = 0.02;

// Floor of cosines in denominators (numpy _COS_MIN): grazing gives the
// limit Lambda -> large, G -> 0, never a division by zero.
const float CF_COS_MIN = 1.0e-7;

// Burley 2012 / Filament / OpenPBR: alpha_g = r^2 of the perceptual
// roughness, r clamped to [CF_ROUGHNESS_MIN, 1].
float cf_alpha_g_from_roughness(float roughness)
{
    float r = clamp(roughness, CF_ROUGHNESS_MIN, 1.0);
    return r * r;
}

// Walter et al. 2007, Eq. 33: GGX D = a^2 / (pi (cos^2 (a^2 - 1) + 1)^2),
// written cos^2 a^2 + sin^2 with sin^2 = H.x^2 + H.y^2, exact near the peak
// where 1 - cos^2 would cancel in float32. Zero below the surface.
float cf_ggx_D(vec3 H, float alpha_g)
{
    float a2 = alpha_g * alpha_g;
    float sin2 = H.x * H.x + H.y * H.y;
    float d = H.z * H.z * a2 + sin2;
    // d >= a2 * (H.z^2 + sin2) > 0 for a unit H and alpha_g <= 1.
    return H.z > 0.0 ? a2 / (CF_PI * d * d) : 0.0;
}

// Heitz 2014, Eq. 72: Lambda = (-1 + sqrt(1 + a^2 tan^2)) / 2 for GGX.
float cf_smith_lambda(float NdotX, float alpha_g)
{
    float mu = clamp(NdotX, CF_COS_MIN, 1.0);
    float tan2 = (1.0 - mu * mu) / (mu * mu);
    return 0.5 * (sqrt(1.0 + alpha_g * alpha_g * tan2) - 1.0);
}

// Heitz 2014, Eq. 43: Smith masking G1 = 1 / (1 + Lambda).
float cf_smith_G1(float NdotV, float alpha_g)
{
    return 1.0 / (1.0 + cf_smith_lambda(NdotV, alpha_g));
}

// Heitz 2014, Eq. 99: height-correlated masking-shadowing
// G2 = 1 / (1 + Lambda(V) + Lambda(L)); 0 if either is below the surface.
float cf_smith_G2(float NdotV, float NdotL, float alpha_g)
{
    float G = 1.0 / (1.0 + cf_smith_lambda(NdotV, alpha_g) + cf_smith_lambda(NdotL, alpha_g));
    return (NdotV > 0.0 && NdotL > 0.0) ? G : 0.0;
}

// Snell through the coat's flat mean surface: a direction in air seen from
// inside a coat of index eta_i >= 1 (tangential part / eta_i), still
// pointing away from the surface (fitting.shading.microfacet.refract_into_coat).
vec3 cf_refract_into_coat(vec3 W, float eta_i)
{
    vec2 t = W.xy / max(eta_i, 1.0);
    // eta_i >= 1 keeps the argument in [0, 1]; the max absorbs rounding.
    return vec3(t, sqrt(max(1.0 - dot(t, t), 0.0)));
}

// Born & Wolf 1999, Sec. 1.5.2: unpolarised Fresnel reflectance from air
// into a dielectric of index eta_i (fitting.optics.fresnel.fresnel_dielectric with
// eta_i = 1, eta_t = eta_i); exactly 0 at eta_i = 1 (no interface).
float cf_fresnel_dielectric(float NdotV, float eta_i)
{
    float mu = cf_saturate(NdotV);
    float cos_t = sqrt(max(1.0 - (1.0 - mu * mu) / (eta_i * eta_i), 0.0));
    // Both denominators are >= 0 and vanish only at grazing with eta_i = 1.
    float rs = (mu - eta_i * cos_t) / max(mu + eta_i * cos_t, CF_FLT_MIN);
    float rp = (eta_i * mu - cos_t) / max(eta_i * mu + cos_t, CF_FLT_MIN);
    return eta_i == 1.0 ? 0.0 : 0.5 * (rs * rs + rp * rp);
}

// D G2 / (4 NdotL NdotV): the Fresnel-free part of the GGX BRDF at H.
float cf_ggx_DG(vec3 V, vec3 L, vec3 H, float alpha_g)
{
    float D = cf_ggx_D(H, alpha_g);
    float G = cf_smith_G2(V.z, L.z, alpha_g);
    return D * G / (4.0 * max(V.z, CF_COS_MIN) * max(L.z, CF_COS_MIN));
}

// v + l = 0 only for opposite directions, where the BRDF is 0 anyway.
vec3 cf_half_vector(vec3 V, vec3 L)
{
    vec3 s = V + L;
    return s / max(length(s), CF_FLT_MIN);
}

// Walter et al. 2007, Eq. 20 with Vernooij 2024, Eq. 1 at VdotH: the
// immersed BRDF (camera, light and metal in one medium of index eta_i,
// whose F0, a, alpha are given; fitting.shading.microfacet.specular_brdf).
vec3 cf_microfacet_immersed(vec3 V, vec3 L, float roughness, vec3 F0, vec3 a, vec3 alpha)
{
    vec3 H = cf_half_vector(V, L);
    float VdotH = cf_saturate(dot(V, H));
    float alpha_g = cf_alpha_g_from_roughness(roughness);
    return cf_ggx_DG(V, L, H, alpha_g) * cf_coated_conductor_eq1(VdotH, F0, a, alpha);
}

// Weidlich & Wilkie 2007, Eq. 4-6 (the OpenPBR coat): the coat's own GGX
// lobe with dielectric Fresnel plus the metal's immersed lobe at the
// directions refracted into the coat, times the transmission in and out,
// over eta_i^2 (the change of projected solid angle across the interface).
// At eta_i = 1 the coat terms vanish: this is cf_microfacet_immersed.
vec3 cf_microfacet_coated(vec3 V, vec3 L, float roughness, vec3 F0, vec3 a, vec3 alpha,
                          float eta_i, float coat_roughness)
{
    float eta = max(eta_i, 1.0);
    vec3 H = cf_half_vector(V, L);
    float VdotH = cf_saturate(dot(V, H));
    float coat = cf_ggx_DG(V, L, H, cf_alpha_g_from_roughness(coat_roughness))
               * cf_fresnel_dielectric(VdotH, eta);
    float transmission = (1.0 - cf_fresnel_dielectric(V.z, eta))
                       * (1.0 - cf_fresnel_dielectric(L.z, eta));
    vec3 base = cf_microfacet_immersed(cf_refract_into_coat(V, eta), cf_refract_into_coat(L, eta),
                                       roughness, F0, a, alpha);
    vec3 f = vec3(coat) + transmission / (eta * eta) * base;
    return (V.z > 0.0 && L.z > 0.0) ? f : vec3(0.0);
}

// The Hammersley point i of n (fitting.shading.lut._hammersley):
// ((i + 1/2) / n, the base-2 radical inverse of i), the pre-integration's
// deterministic quadrature. GLSL ES 3.00 has no bitfieldReverse: the 32
// bits are swapped in halves, bytes, nibbles, pairs and single bits.
vec2 cf_hammersley(int i, int n)
{
    uint bits = uint(i);
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    // 2^-32; float(bits) rounds to 24 bits, 6e-8 relative.
    return vec2((float(i) + 0.5) / float(n), float(bits) * 2.3283064365386963e-10);
}

// Heitz 2018, Listing 1: a GGX microfacet normal drawn from the normals
// visible from V by the uniform numbers u in [0, 1)^2
// (fitting.shading.microfacet.sample_visible_normal). With the mirrored
// light L = 2 (V.H) H - V the directional albedo's estimator is
// F(V.H) G2 / G1(V).
vec3 cf_sample_visible_normal(vec3 V, float alpha_g, vec2 u)
{
    // The view stretched to the hemisphere configuration.
    vec3 Vh = normalize(vec3(alpha_g * V.xy, V.z));
    float lensq = dot(Vh.xy, Vh.xy);
    // Normal view (lensq = 0): any tangent will do, take +x.
    vec3 T1 = lensq > 0.0 ? vec3(-Vh.y, Vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
    vec3 T2 = cross(Vh, T1);
    float r = sqrt(u.x);
    float phi = 2.0 * CF_PI * u.y;
    float t1 = r * cos(phi);
    float t2 = r * sin(phi);
    float s = 0.5 * (1.0 + Vh.z);
    // The saturates absorb rounding of t1^2 + t2^2 past 1.
    t2 = (1.0 - s) * sqrt(cf_saturate(1.0 - t1 * t1)) + s * t2;
    vec3 Nh = t1 * T1 + t2 * T2 + sqrt(cf_saturate(1.0 - t1 * t1 - t2 * t2)) * Vh;
    // Back to the ellipsoid; z >= 0 keeps the normal above the surface.
    return normalize(vec3(alpha_g * Nh.xy, max(Nh.z, 0.0)));
}

#endif
