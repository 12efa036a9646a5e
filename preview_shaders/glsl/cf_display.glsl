// The preview display transform (preview_shaders.display): linear ACEScg to
// linear sRGB (CAT02 from the ACES white to D65), clipped to [0, 1], sRGB
// encoded (IEC 61966-2-1).
#ifndef CF_DISPLAY_GLSL
#define CF_DISPLAY_GLSL

// preview_shaders.display.ACEScg_to_sRGB_matrix(), columns (GLSL is
// column-major): M * rgb.
const mat3 CF_ACESCG_TO_SRGB = mat3(
    1.704887331, -0.129520935, -0.024127060,
    -0.624157274, 1.138399326, -0.124620612,
    -0.080886774, -0.008779242, 1.148822110);

vec3 cf_srgb_encode(vec3 linear)
{
    vec3 x = clamp(linear, 0.0, 1.0);
    vec3 high = 1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055;
    return mix(high, 12.92 * x, vec3(lessThanEqual(x, vec3(0.0031308))));
}

vec3 cf_display(vec3 acescg)
{
    return cf_srgb_encode(CF_ACESCG_TO_SRGB * acescg);
}

#endif
