// The preview environment prefiltered per roughness for the split sum
// (Karis 2013): equirect slices at roughness j / (n - 1), made once per
// environment by preview_shaders.rough.prefilter_equirect (the GGX lobe
// with N = V = R) and sent by GET /api/v1/environments/{name}/prefiltered.
#ifndef CF_PREFILTERED_ENVIRONMENT_GLSL
#define CF_PREFILTERED_ENVIRONMENT_GLSL

#include "cf_common.glsl"
#include "cf_microfacet.glsl"

#ifdef GL_ES
precision highp sampler2DArray;
#endif

// Equirect coordinates of a direction (y up, u = 0.5 towards -z):
// preview_shaders.rough.equirect_directions is the inverse.
vec2 cf_equirect_uv(vec3 d)
{
    d = normalize(d);
    float u = 0.5 + atan(d.x, -d.z) / (2.0 * CF_PI);
    float v = acos(clamp(d.y, -1.0, 1.0)) / CF_PI;
    return vec2(u, v);
}

// The lighting of a GGX lobe of perceptual `roughness` around the mirror
// direction R, from R's equirect coordinates uv (cf_equirect_uv) and the
// environment itself along R (`mirror`, cf_environment): the slices (layer
// j at roughness j / (layers - 1), bilinear within a layer: u repeats, v
// clamps) interpolated linearly in roughness. Layer 0, a mirror, is
// replaced by `mirror`, which is exact there and sharper than its texels,
// so roughness 0 gives the environment itself and the image is continuous
// from it. The caller evaluates the environment once for every lobe.
vec3 cf_prefiltered_lighting(sampler2DArray slices, vec3 mirror, vec2 uv, float roughness)
{
    int layers = textureSize(slices, 0).z;
    float z = cf_saturate(roughness) * float(layers - 1);
    // The layer below z, kept <= layers - 2 so that the one above exists.
    int j = min(int(floor(z)), layers - 2);
    vec3 low = j == 0 ? mirror : texture(slices, vec3(uv, float(j))).rgb;
    vec3 high = texture(slices, vec3(uv, float(j + 1))).rgb;
    return mix(low, high, z - float(j));
}

#endif
