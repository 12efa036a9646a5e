// The model kinds' Fresnel for the node material (node_material.js), each
// written once over an arithmetic `m`: three's TSL functions (add, mul,
// sqrt, mix, step, ...) build the node graph, NUMBERS (below) evaluate the
// same formula on numbers, one channel at a time, which the tests compare
// with the registry's own numpy (tests/static/test_three_node_material.py).
// Each kind is found by its GLSL function (generated/kinds.js glslFunction),
// whose term-by-term twin it is; no kind is named here.
//
// A kind's entry: `parameters(model)`, its per-channel values at the
// material's coat index from the float16 coefficients (what its GLSL
// unpacks), done once on the CPU as the GLSL's Horner form does per pixel;
// `fresnel(m, mu, eta, P)`, its reflectance (linear ACEScg) at cosine mu
// seen from the coat's index eta.

import { halfBits } from "./packing.js";

const FLT_MIN = 1.17549435e-38;
const ALPHA_MIN = 1.0e-3;

/** The float16 value `x` rounds to, as unpackHalf2x16 gives it back. */
export function half(x) {
  const h = halfBits(x);
  const sign = h & 0x8000 ? -1 : 1;
  const exponent = (h >>> 10) & 0x1f;
  const mantissa = h & 0x3ff;
  if (exponent === 0) return sign * mantissa * 2 ** -24;
  if (exponent === 0x1f) return mantissa ? NaN : sign * Infinity;
  return sign * (1 + mantissa / 1024) * 2 ** (exponent - 15);
}

/** Arithmetic on numbers, GLSL's meaning (step(edge, x) is 1 for x >= edge; mix(a, b, t) = a (1 - t) + b t). */
export const NUMBERS = Object.freeze({
  add: (a, b) => a + b,
  sub: (a, b) => a - b,
  mul: (a, b) => a * b,
  div: (a, b) => a / b,
  sqrt: Math.sqrt,
  abs: Math.abs,
  max: Math.max,
  min: Math.min,
  exp2: (x) => 2 ** x,
  log2: Math.log2,
  step: (edge, x) => (x >= edge ? 1 : 0),
  mix: (a, b, t) => a * (1 - t) + b * t,
  clamp: (x, lo, hi) => Math.min(Math.max(x, lo), hi),
});

/** The normalised coat index t of cf_normalised_eta_i (0 for a single-index fit). */
function normalised(eta, [lo, hi]) {
  const width = hi - lo;
  return width > 0 ? Math.min(Math.max((eta - lo) / Math.max(width, FLT_MIN), 0), 1) : 0;
}

/** The GLSL's cf_coated_conductor: Vernooij 2024, Eq. 2 on the CPU (Horner in t), Eq. 1 in `m`. */
const polynomialInCoatIndex = {
  parameters({ coefficients, coatIor, etaIRange, degree }) {
    const t = normalised(coatIor, etaIRange);
    const at = (row) => {
      const c = [0, 1, 2].map((j) => (j <= degree ? half(row[j] ?? 0) : 0));
      return c[0] + t * (c[1] + t * c[2]);
    };
    const channels = (p) => [0, 1, 2].map((c) => at(coefficients[p][c]));
    return { F0: channels("F0"), a: channels("a"), alpha: channels("alpha").map((x) => Math.max(x, ALPHA_MIN)) };
  },
  fresnel(m, mu_in, eta, { F0, a, alpha }) {
    const mu = m.clamp(mu_in, 0, 1);
    const x = m.sub(1, mu);
    const x2 = m.mul(x, x);
    const x5 = m.mul(m.mul(x2, x2), x);
    const xAlpha = m.exp2(m.mul(alpha, m.log2(x)));
    return m.sub(m.add(m.mul(F0, m.sub(1, x5)), x5), m.mul(m.mul(a, mu), xAlpha));
  },
};

/** Principal square root of re + i im (cf_complex_sqrt, Kahan's branch order): [re, im]. */
function complexSqrt(m, re, im) {
  const modulus = m.sqrt(m.add(m.mul(re, re), m.mul(im, im)));
  const t = m.sqrt(m.mul(0.5, m.add(modulus, m.abs(re))));
  const u = m.div(m.mul(0.5, im), m.max(t, FLT_MIN));
  const right = m.step(0, re);
  const signedT = m.mix(m.sub(0, t), t, m.step(0, im));
  return [m.mix(m.abs(u), t, right), m.mix(signedT, u, right)];
}

/** The GLSL's cf_rgb_conductor: the exact Fresnel of n + i k seen from index eta (cf_fresnel_conductor). */
const complexIndex = {
  parameters({ coefficients }) {
    return { n: coefficients.n.map(half), k: coefficients.k.map(half) };
  },
  fresnel(m, mu_in, eta, { n, k }) {
    const mu = m.clamp(mu_in, 0, 1);
    const er = m.div(n, eta);
    const ei = m.div(k, eta);
    const eta2Re = m.sub(m.mul(er, er), m.mul(ei, ei));
    const eta2Im = m.mul(m.mul(2, er), ei);
    const eta2Abs2 = m.max(m.add(m.mul(eta2Re, eta2Re), m.mul(eta2Im, eta2Im)), FLT_MIN);
    const sin2I = m.sub(1, m.mul(mu, mu));
    const sin2Re = m.div(m.mul(sin2I, eta2Re), eta2Abs2);
    const sin2Im = m.div(m.mul(m.sub(0, sin2I), eta2Im), eta2Abs2);
    const [ctRe, ctIm] = complexSqrt(m, m.sub(1, sin2Re), m.sub(0, sin2Im));
    const ectRe = m.sub(m.mul(er, ctRe), m.mul(ei, ctIm));
    const ectIm = m.add(m.mul(er, ctIm), m.mul(ei, ctRe));
    const square = (x) => m.mul(x, x);
    const ns2 = m.add(square(m.sub(mu, ectRe)), square(ectIm));
    const ds2 = m.add(square(m.add(mu, ectRe)), square(ectIm));
    const np2 = m.add(square(m.sub(m.mul(er, mu), ctRe)), square(m.sub(m.mul(ei, mu), ctIm)));
    const dp2 = m.add(square(m.add(m.mul(er, mu), ctRe)), square(m.add(m.mul(ei, mu), ctIm)));
    const R = m.mul(0.5, m.add(m.div(ns2, m.max(ds2, FLT_MIN)), m.div(np2, m.max(dp2, FLT_MIN))));
    return m.clamp(R, 0, 1);
  },
};

/** Each kind's node-material model by its GLSL function (generated/kinds.js glslFunction). */
export const NODE_MODELS = Object.freeze({
  cf_coated_conductor: polynomialInCoatIndex,
  cf_rgb_conductor: complexIndex,
});

/** The node model of generated kind `kind`, or an Error naming the kind when the package has none. */
export function nodeModelOf(kind) {
  const model = NODE_MODELS[kind.glslFunction];
  if (!model) throw new Error(`the node material has no TSL twin of ${kind.glslFunction} (kind ${kind.name})`);
  return model;
}

/**
 * The reflectance of extension object `model` of kind `kind` at cosines
 * `mus` seen from its coat index, on numbers: [[R, G, B], ...].
 */
export function evaluateModel(kind, model, mus) {
  const node = nodeModelOf(kind);
  const P = node.parameters(model);
  return mus.map((mu) => [0, 1, 2].map((c) => {
    const channel = Object.fromEntries(Object.entries(P).map(([p, v]) => [p, v[c]]));
    return node.fresnel(NUMBERS, mu, model.coatIor, channel);
  }));
}
