// The spectral reference as a texture over (cos theta, eta_i): what
// GET /api/v1/fits/{id}/reference-texture sends (float32 RGB, linear ACEScg,
// width = cos theta evenly over [0, 1], height = eta_i evenly over its
// range). Used as the Fresnel term of the preview's reference view.
#ifndef CF_REFERENCE_TEXTURE_GLSL
#define CF_REFERENCE_TEXTURE_GLSL

#include "cf_common.glsl"

// Bilinear interpolation with texelFetch, exactly as
// fitting.fits.curves_base.CurveBase.rgb does it in numpy (eta_i clamped to the range;
// a one-row texture is a single index). Float textures are not filterable
// everywhere (OES_texture_float_linear), so the filter is written out.
vec3 cf_reference_lookup(sampler2D lut, float NdotV, float eta_i, vec2 eta_i_range)
{
    ivec2 size = textureSize(lut, 0);
    float u = cf_saturate(NdotV) * float(size.x - 1);
    int i0 = min(int(floor(u)), size.x - 2);
    float fu = u - float(i0);
    float width = eta_i_range.y - eta_i_range.x;
    float v = size.y > 1 && width > 0.0
        ? clamp((eta_i - eta_i_range.x) / width, 0.0, 1.0) * float(size.y - 1) : 0.0;
    int j0 = min(int(floor(v)), max(size.y - 2, 0));
    int j1 = min(j0 + 1, size.y - 1);
    float fv = v - float(j0);
    vec3 top = mix(texelFetch(lut, ivec2(i0, j0), 0).rgb, texelFetch(lut, ivec2(i0 + 1, j0), 0).rgb, fu);
    vec3 bottom = mix(texelFetch(lut, ivec2(i0, j1), 0).rgb, texelFetch(lut, ivec2(i0 + 1, j1), 0).rgb, fu);
    return mix(top, bottom, fv);
}

#endif
