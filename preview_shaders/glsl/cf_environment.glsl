// Preview environments: radiance in linear ACEScg seen along a world
// direction (y up, the camera on +z looking down -z).
#ifndef CF_ENVIRONMENT_GLSL
#define CF_ENVIRONMENT_GLSL

#include "cf_outdoor.glsl"

const int CF_ENVIRONMENT_WHITE_SKY = 0;
const int CF_ENVIRONMENT_STUDIO = 1;

// Uniform white sky of radiance 1, as in the paper's validation renders
// (Vernooij 2024, Section 4.2): a smooth sphere then shows F(cos theta).
vec3 cf_white_sky(vec3 direction)
{
    return vec3(1.0);
}

// Soft-edged rectangular light: the direction's gnomonic projection on the
// light's plane, inside half_size with a smooth border of width softness.
float cf_soft_rect(vec3 direction, vec3 axis, vec3 u_axis, vec3 v_axis,
                   vec2 half_size, float softness)
{
    float facing = dot(direction, axis);
    // Directions at or behind the light's plane never see it (and would
    // divide by zero in the projection).
    if (facing <= 1.0e-3)
        return 0.0;
    vec2 uv = abs(vec2(dot(direction, u_axis), dot(direction, v_axis)) / facing);
    vec2 inside = 1.0 - smoothstep(half_size - softness, half_size + softness, uv);
    return inside.x * inside.y;
}

// Photo studio: grey cyclorama over a dark floor, a large overhead softbox,
// a tall key strip on the left, a warm kicker behind on the right and a dim
// frontal fill, so that a metal sphere shows its colour at normal incidence
// and its edge behaviour toward the rim.
vec3 cf_studio_environment(vec3 direction)
{
    vec3 d = normalize(direction);
    vec3 cyclorama = mix(vec3(0.10, 0.105, 0.11), vec3(0.32, 0.33, 0.35),
                         smoothstep(-0.1, 0.9, d.y));
    vec3 floor_colour = vec3(0.035, 0.033, 0.030);
    // A soft horizon line instead of a hard edge.
    vec3 L = mix(floor_colour, cyclorama, smoothstep(-0.06, 0.02, d.y));

    vec3 top_axis = normalize(vec3(0.0, 1.0, 0.35));
    vec3 top_u = vec3(1.0, 0.0, 0.0);
    vec3 top_v = normalize(cross(top_axis, top_u));
    L += vec3(1.6) * cf_soft_rect(d, top_axis, top_u, top_v, vec2(0.9, 0.55), 0.15);

    vec3 key_axis = normalize(vec3(-1.0, 0.15, 0.45));
    vec3 key_u = normalize(cross(vec3(0.0, 1.0, 0.0), key_axis));
    vec3 key_v = cross(key_axis, key_u);
    L += vec3(1.3, 1.28, 1.25) * cf_soft_rect(d, key_axis, key_u, key_v, vec2(0.12, 0.9), 0.05);

    vec3 kick_axis = normalize(vec3(1.0, 0.25, -0.6));
    vec3 kick_u = normalize(cross(vec3(0.0, 1.0, 0.0), kick_axis));
    vec3 kick_v = cross(kick_axis, kick_u);
    L += vec3(1.2, 0.95, 0.7) * cf_soft_rect(d, kick_axis, kick_u, kick_v, vec2(0.25, 0.6), 0.1);

    // Dim frontal fill: keeps the sphere's centre (which reflects the
    // camera side) from going black.
    L += vec3(0.4) * pow(max(d.z, 0.0), 3.0);
    return L;
}

// CF_ENVIRONMENT_* (CF_ENVIRONMENT_OUTDOOR from cf_outdoor.glsl); any
// other value is the white sky.
vec3 cf_environment(int environment, vec3 direction)
{
    if (environment == CF_ENVIRONMENT_OUTDOOR)
        return cf_outdoor_environment(direction);
    if (environment == CF_ENVIRONMENT_STUDIO)
        return cf_studio_environment(direction);
    return cf_white_sky(direction);
}

#endif
