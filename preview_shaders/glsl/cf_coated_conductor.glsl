// The coated-conductor Fresnel model of Vernooij (2024), Eq. 1 and 2: the
// GLSL mirror of fitting/models/coated_conductor.py, term by term.
//
// Coefficient layout (fitting.models.coated_conductor): coefficients[p][c][j], parameter p in
// (F0, a, alpha), channel c in (R, G, B), power j in (1, t, t^2); 27 values
// in that order. Here each parameter is one mat3 whose column c holds the
// powers of channel c, so T * M (T = (1, t, t^2)) gives the three channels.
//
// Reference: H. B. Vernooij, "A Fresnel Model for Coated Materials",
// Eurographics 2024 (Short Papers).
#ifndef CF_COATED_CONDUCTOR_GLSL
#define CF_COATED_CONDUCTOR_GLSL

#include "cf_common.glsl"

// Normalised coating index t = (eta_i - lo) / (hi - lo), clamped to [0, 1]
// (fitting.models.coated_conductor.normalised_eta_i). A single-index fit (hi == lo) has t = 0.
float cf_normalised_eta_i(float eta_i, vec2 eta_i_range)
{
    float width = eta_i_range.y - eta_i_range.x;
    // A select, not a branch: software rasterisers run both sides of a
    // branch under masks; the floor keeps the unused quotient finite.
    float t = clamp((eta_i - eta_i_range.x) / max(width, CF_FLT_MIN), 0.0, 1.0);
    return width > 0.0 ? t : 0.0;
}

// Row j of M (power j of t for the three channels) in Horner form: the
// three quadratics of one parameter at t.
vec3 cf_horner(float t, mat3 M)
{
    vec3 c0 = vec3(M[0][0], M[1][0], M[2][0]);
    vec3 c1 = vec3(M[0][1], M[1][1], M[2][1]);
    vec3 c2 = vec3(M[0][2], M[1][2], M[2][2]);
    return c0 + t * (c1 + t * c2);
}

// Vernooij 2024, Eq. 2 (in t instead of eta_i): F0, a and alpha per channel,
// each c0 + c1 t + c2 t^2 (fitting.models.coated_conductor.model_parameters). alpha is clamped
// to CF_ALPHA_MIN there, as in numpy.
void cf_coated_conductor_parameters(float t, mat3 C_F0, mat3 C_a, mat3 C_alpha,
                                    out vec3 F0, out vec3 a, out vec3 alpha)
{
    // Horner's c0 + t (c1 + t c2) per channel on the rows of the mat3s
    // (power j of the three channels): 18 multiply-adds where T * M takes 27
    // multiplies and 18 adds. Equal to numpy's sum of powers to float32 rounding.
    F0 = cf_horner(t, C_F0);
    a = cf_horner(t, C_a);
    alpha = max(cf_horner(t, C_alpha), vec3(CF_ALPHA_MIN));
}

// Eq. 1 from constants the CPU computed (fitting.models.coated_conductor.collapse_to_eta_i:
// alpha already clamped to CF_ALPHA_MIN): the scene-specialised model. One
// shared log2 for the three (1 - mu)^alpha (pow's own expansion, written
// out), (1 - mu)^5 by multiplication, F0 + (1 - F0) x^5 as one multiply-add
// per channel. At mu = 1, log2(0) = -inf and exp2(-inf) = 0: the term
// vanishes as pow(0, alpha) does. Equal to cf_coated_conductor_eq1 to float32
// rounding, without its clamp of alpha.
vec3 cf_coated_conductor_eq1_lean(float NdotV, vec3 F0, vec3 a, vec3 alpha)
{
    float mu = cf_saturate(NdotV);
    float x = 1.0 - mu;
    float x2 = x * x;
    float x5 = x2 * x2 * x;
    vec3 x_alpha = exp2(alpha * log2(x));
    return F0 * (1.0 - x5) + x5 - a * mu * x_alpha;
}

// Vernooij 2024, Eq. 1 (Lazanyi & Szirmay-Kalos 2005 error term on Schlick):
// F = F0 + (1 - F0)(1 - mu)^5 - a mu (1 - mu)^alpha per channel
// (fitting.models.coated_conductor.model_from_parameters). This alone is the scene-specialised
// model: with eta_i constant, F0, a and alpha are collapsed on the CPU.
vec3 cf_coated_conductor_eq1(float NdotV, vec3 F0, vec3 a, vec3 alpha)
{
    return cf_coated_conductor_eq1_lean(NdotV, F0, a, max(alpha, vec3(CF_ALPHA_MIN)));
}

// The general model from float coefficients (Vernooij 2024, Eq. 1 and 2).
vec3 cf_coated_conductor(float NdotV, float eta_i, vec2 eta_i_range,
                         mat3 C_F0, mat3 C_a, mat3 C_alpha)
{
    vec3 F0, a, alpha;
    float t = cf_normalised_eta_i(eta_i, eta_i_range);
    cf_coated_conductor_parameters(t, C_F0, C_a, C_alpha, F0, a, alpha);
    // alpha is clamped already: Eq. 1 without a second clamp.
    return cf_coated_conductor_eq1_lean(NdotV, F0, a, alpha);
}

// Decodes the 27 float16 coefficients packed two per uint32, the earlier one
// in the low 16 bits (fitting.models.pack.halves_to_uint32), so unpackHalf2x16(w).x
// is the earlier half; the 28th half is padding. Written out rather than
// looped through a float[27] so no compiler needs a local array for it.
void cf_unpack_coefficients(uint words[14], out mat3 C_F0, out mat3 C_a, out mat3 C_alpha)
{
    vec2 h0 = unpackHalf2x16(words[0]), h1 = unpackHalf2x16(words[1]);
    vec2 h2 = unpackHalf2x16(words[2]), h3 = unpackHalf2x16(words[3]);
    vec2 h4 = unpackHalf2x16(words[4]), h5 = unpackHalf2x16(words[5]);
    vec2 h6 = unpackHalf2x16(words[6]), h7 = unpackHalf2x16(words[7]);
    vec2 h8 = unpackHalf2x16(words[8]), h9 = unpackHalf2x16(words[9]);
    vec2 h10 = unpackHalf2x16(words[10]), h11 = unpackHalf2x16(words[11]);
    vec2 h12 = unpackHalf2x16(words[12]), h13 = unpackHalf2x16(words[13]);
    C_F0 = mat3(h0.x, h0.y, h1.x, h1.y, h2.x, h2.y, h3.x, h3.y, h4.x);
    C_a = mat3(h4.y, h5.x, h5.y, h6.x, h6.y, h7.x, h7.y, h8.x, h8.y);
    C_alpha = mat3(h9.x, h9.y, h10.x, h10.y, h11.x, h11.y, h12.x, h12.y, h13.x);
}

// The general model from the packed halves, exactly what a renderer uploads.
vec3 cf_coated_conductor_packed(float NdotV, float eta_i, vec2 eta_i_range, uint words[14])
{
    mat3 C_F0, C_a, C_alpha;
    cf_unpack_coefficients(words, C_F0, C_a, C_alpha);
    return cf_coated_conductor(NdotV, eta_i, eta_i_range, C_F0, C_a, C_alpha);
}

// The general model from per-power coefficients: column j of P_F0, P_a and
// P_alpha holds power j of t for the three channels (the transpose of
// cf_coated_conductor's per-channel columns), and t = clamp(eta_i s + o, 0, 1)
// with t_map = (s, o) = (1 / (hi - lo), -lo / (hi - lo)), (0, 0) for a
// single-index fit (fitting.models.coated_conductor.lean_constants): the
// per-material work done once on the CPU, as a renderer does Lazanyi's F0
// and a; Eq. 2 in Horner form. Equal to cf_coated_conductor to float32 rounding.
vec3 cf_coated_conductor_lean(float NdotV, float eta_i, vec2 t_map,
                              mat3 P_F0, mat3 P_a, mat3 P_alpha)
{
    float t = clamp(eta_i * t_map.x + t_map.y, 0.0, 1.0);
    vec3 F0 = P_F0[0] + t * (P_F0[1] + t * P_F0[2]);
    vec3 a = P_a[0] + t * (P_a[1] + t * P_a[2]);
    vec3 alpha = max(P_alpha[0] + t * (P_alpha[1] + t * P_alpha[2]), vec3(CF_ALPHA_MIN));
    return cf_coated_conductor_eq1_lean(NdotV, F0, a, alpha);
}

#endif
