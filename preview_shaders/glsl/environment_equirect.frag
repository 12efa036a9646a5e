#version 430
// The preview environment (cf_environment.glsl) drawn into an equirect
// target, one texel per direction at its centre (preview_shaders.rough
// prefilters it per roughness).
#include "cf_environment.glsl"

uniform int u_environment;
uniform vec2 u_size;
out vec4 out_radiance;

void main()
{
    vec2 uv = gl_FragCoord.xy / u_size;  // texel centres; row 0 is v = 0 (up)
    float phi = (uv.x - 0.5) * 2.0 * 3.14159265358979;
    float theta = uv.y * 3.14159265358979;
    vec3 d = vec3(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
    out_radiance = vec4(cf_environment(u_environment, d), 1.0);
}
