// Shared helpers of the coated-conductor shaders (prefix cf_).
#ifndef CF_COMMON_GLSL
#define CF_COMMON_GLSL

// Lower clamp of the exponent alpha, as fitting.models.coated_conductor.ALPHA_MIN: keeps
// (1 - mu)^alpha finite at mu = 1 (GLSL pow(0, y) is undefined for y <= 0).
const float CF_ALPHA_MIN = 1.0e-3;

// Smallest normal float32: denominators are kept above it so a degenerate
// interface gives the physical limit instead of NaN.
const float CF_FLT_MIN = 1.17549435e-38;

// mu = cos(theta) from an interpolated or reconstructed normal can leave
// [0, 1] by rounding; every model is defined on [0, 1] (numpy clips too).
float cf_saturate(float x)
{
    return clamp(x, 0.0, 1.0);
}

// x^5 by multiplication: exact enough and cheaper than pow.
float cf_pow5(float x)
{
    float x2 = x * x;
    return x2 * x2 * x;
}

#endif
