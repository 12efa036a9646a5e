#version 430
// Writes the 27 decoded coefficients, one per pixel of a 27 x 1 target, to
// check that cf_unpack_coefficients gives exactly numpy's float16 values.
#include "cf_coated_conductor.glsl"

uniform uint cf_words[14];

layout(location = 0) out vec4 out_value;

void main()
{
    mat3 C[3];
    cf_unpack_coefficients(cf_words, C[0], C[1], C[2]);
    int i = int(gl_FragCoord.x);
    // Layout index i = 9 p + 3 c + j is column c, row j of parameter p.
    out_value = vec4(C[i / 9][(i / 3) % 3][i % 3], 0.0, 0.0, 1.0);
}
