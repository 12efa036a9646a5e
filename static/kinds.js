// The model kinds the browser draws: for each kind the API serves
// (FitPublic.model), how its coefficients become the words a renderer
// uploads, how the preview's shaders are told the kind, and how the editor
// writes its coefficients out. The browser's twin of the registry in
// fitting/models/kinds.py; a fit of a kind not listed here is refused by
// name (modelKind), never drawn as another kind.
//
// No DOM, no WebGL: imported by the preview (preview.js, splitsum.js), the
// editor's views and the three.js material, and by the node unit tests.

// ------------------------------------------------------------ float16 halves

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

/** Halves two to a uint32 word, the earlier in the low 16 bits (fitting.pack.halves_to_uint32), padded to `count` words. */
export function wordsOf(halves, count = 14) {
  const words = new Uint32Array(count);
  for (let k = 0; 2 * k < halves.length && k < count; k++) {
    words[k] = ((halves[2 * k] ?? 0) | ((halves[2 * k + 1] ?? 0) << 16)) >>> 0;
  }
  return words;
}

/**
 * The 14 uint32 words of a coated-conductor fit (fitting.pack.halves_to_uint32):
 * coefficients[p][c][j] for p in (F0, a, alpha), two halves a word, the
 * earlier in the low 16 bits; powers beyond the fit's degree are 0.
 */
export function packedWords(coefficients) {
  const halves = [];
  for (const p of ["F0", "a", "alpha"]) {
    for (let c = 0; c < 3; c++) {
      for (let j = 0; j < 3; j++) halves.push(halfBits(coefficients[p][c][j] ?? 0));
    }
  }
  return wordsOf(halves);
}

/**
 * The words of an rgb-conductor fit: its 6 halves n_R, n_G, n_B, k_R, k_G,
 * k_B in 3 words (cf_unpack_rgb_conductor), the rest of the preview's 14 zero.
 */
export function rgbConductorWords(coefficients) {
  return wordsOf([...coefficients.n, ...coefficients.k].map(halfBits));
}

const row = (values) => values.map((v) => v.toFixed(5)).join(", ");

// ------------------------------------------------------------ the registry

/**
 * name -> {
 *   parameters: the coefficients' keys,
 *   shaderKind: CF_RGB_CONDUCTOR's value in shader_ball.frag (0 or 1),
 *   words(coefficients): Uint32Array(14), what the preview uploads as cf_words,
 *   nk(coefficients): [n, k] per channel for the kinds the exact Fresnel draws, else null,
 *   check(coefficients): throws an Error naming the field when malformed,
 *   describe(fit): the editor's text of its coefficients,
 *   liveInPage: whether the editor solves its live refits in the page (editor/live_solve.js),
 * }
 */
export const MODEL_KINDS = {
  "coated-conductor": {
    parameters: ["F0", "a", "alpha"],
    shaderKind: 0,
    liveInPage: true,
    words: packedWords,
    nk: () => null,
    check(C) {
      for (const p of ["F0", "a", "alpha"]) {
        const ok = Array.isArray(C[p]) && C[p].length === 3 &&
          C[p].every((r) => Array.isArray(r) && r.length >= 1 && r.length <= 3 && r.every(Number.isFinite));
        if (!ok) throw new Error(`\`coefficients.${p}\` of a coated-conductor fit must be three rows of 1 to 3 numbers`);
      }
    },
    describe(fit) {
      const rows = ["F0", "a", "alpha"].map((p) =>
        `${p.padEnd(5)} ` + fit.coefficients[p].map((r, c) => `${"RGB"[c]} [${row(r)}]`).join("  "));
      return `coated-conductor, degree ${fit.degree}, eta_i in [${fit.eta_i_range.join(", ")}]\n${rows.join("\n")}`;
    },
  },
  "rgb-conductor": {
    parameters: ["n", "k"],
    shaderKind: 1,
    liveInPage: false, // its live step (an exact-Fresnel solve from its own guess) stays the server's
    words: rgbConductorWords,
    nk: (C) => [C.n.slice(), C.k.slice()],
    check(C) {
      for (const p of ["n", "k"]) {
        if (!Array.isArray(C[p]) || C[p].length !== 3 || !C[p].every(Number.isFinite)) {
          throw new Error(`\`coefficients.${p}\` of an rgb-conductor fit must be three numbers (R, G, B)`);
        }
      }
    },
    describe(fit) {
      const rows = ["n", "k"].map((p) => `${p.padEnd(5)} R ${row([fit.coefficients[p][0]])}  ` +
        `G ${row([fit.coefficients[p][1]])}  B ${row([fit.coefficients[p][2]])}`);
      return `rgb-conductor (n + i k per channel), eta_i in [${fit.eta_i_range.join(", ")}]\n${rows.join("\n")}`;
    },
  },
};

export const DEFAULT_KIND = "coated-conductor";

/**
 * The kind of `fit` (a FitPublic answer; no `model` means the default
 * kind), its coefficients checked; an Error naming `model` for a kind this
 * page cannot draw.
 */
export function modelKind(fit) {
  const name = fit.model ?? DEFAULT_KIND;
  const kind = MODEL_KINDS[name];
  if (!kind) {
    throw new Error(`\`model\` must be one of ${Object.keys(MODEL_KINDS).join(", ")} to be drawn here, got ${JSON.stringify(name)}`);
  }
  kind.check(fit.coefficients || {});
  return { name, ...kind };
}
