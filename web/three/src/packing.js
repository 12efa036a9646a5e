// The float16 words of a model's coefficients, as the shaders unpack them
// (the kind's cf_preview_model, generated/kinds.js): the package's own copy
// of the editor's static/kinds.js halfBits / wordsOf / wordsFor (the
// package imports nothing outside itself); tests/static/js/three_packing.test.mjs
// checks that the two agree for every kind the server lists.

const f32 = new Float32Array(1);
const u32 = new Uint32Array(f32.buffer);

/** IEEE half bits of `x`, rounded to nearest even (exact for float16 values). */
export function halfBits(x) {
  f32[0] = x;
  const bits = u32[0];
  const sign = (bits >>> 16) & 0x8000;
  const exponent = (bits >>> 23) & 0xff;
  let mantissa = bits & 0x7fffff;
  if (exponent === 0xff) return sign | 0x7c00 | (mantissa ? 0x200 : 0);
  const e = exponent - 112;
  if (e >= 0x1f) return sign | 0x7c00;
  if (e <= 0) {
    if (e < -10) return sign;
    mantissa |= 0x800000;
    const shift = 14 - e;
    let h = mantissa >>> shift;
    const rest = mantissa & ((1 << shift) - 1), half = 1 << (shift - 1);
    if (rest > half || (rest === half && (h & 1))) h += 1;
    return sign | h;
  }
  let h = (e << 10) | (mantissa >>> 13);
  const rest = mantissa & 0x1fff;
  if (rest > 0x1000 || (rest === 0x1000 && (h & 1))) h += 1;
  return sign | h;
}

/** Halves two to a uint32 word, the earlier in the low 16 bits, padded to `count` words. */
export function wordsOf(halves, count = 14) {
  const words = new Uint32Array(count);
  for (let k = 0; 2 * k < halves.length && k < count; k++) {
    words[k] = ((halves[2 * k] ?? 0) | ((halves[2 * k + 1] ?? 0) << 16)) >>> 0;
  }
  return words;
}

/**
 * The 14 uint32 words of coefficients of a kind with `parameters` and
 * `maxDegree` (generated/kinds.js): for each parameter, channel R, G, B,
 * its value (maxDegree 0) or its maxDegree + 1 powers, those beyond the
 * model's degree 0; two halves a word, the earlier in the low 16 bits.
 */
export function wordsFor({ parameters, maxDegree }, coefficients) {
  const halves = [];
  for (const p of parameters) {
    for (let c = 0; c < 3; c++) {
      if (maxDegree === 0) halves.push(halfBits(coefficients[p][c]));
      else for (let j = 0; j <= maxDegree; j++) halves.push(halfBits(coefficients[p][c][j] ?? 0));
    }
  }
  return wordsOf(halves);
}
