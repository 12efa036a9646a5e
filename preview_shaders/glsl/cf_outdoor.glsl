// A bright outdoor-like preview environment (linear ACEScg, y up): a blue
// sky brighter toward the horizon, a warm sun with a soft halo and a dusty
// ground, so that a metal shows its colour against strong light and its
// rim against the sky.
#ifndef CF_OUTDOOR_GLSL
#define CF_OUTDOOR_GLSL

const int CF_ENVIRONMENT_OUTDOOR = 2;

vec3 cf_outdoor_environment(vec3 direction)
{
    vec3 d = normalize(direction);
    float up = clamp(d.y, -1.0, 1.0);
    vec3 zenith = vec3(0.55, 0.85, 1.9);
    vec3 horizon = vec3(2.3, 2.4, 2.5);
    vec3 sky = mix(horizon, zenith, pow(max(up, 0.0), 0.45));
    vec3 ground = mix(vec3(0.34, 0.30, 0.25), vec3(0.16, 0.14, 0.11), smoothstep(0.0, -0.6, up));
    vec3 L = mix(ground, sky, smoothstep(-0.03, 0.03, up));
    vec3 sun_axis = normalize(vec3(-0.45, 0.55, 0.7));
    float c = dot(d, sun_axis);
    // Disc of ~4 degrees (cos 0.9976) with a soft edge, and a wide halo.
    L += vec3(40.0, 36.0, 30.0) * smoothstep(0.9965, 0.9980, c);
    L += vec3(1.2, 1.0, 0.7) * pow(max(c, 0.0), 24.0);
    return L;
}

#endif
