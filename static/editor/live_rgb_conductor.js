// The live step of the exact-Fresnel conductor kind in the page: per
// channel n, k such that the exact Fresnel reflectance of the relative
// index (n_c + i k_c) / eta_i follows the live target, as the server's live
// step solves it (fitting.fits.curves_steps.bounded_fit with LIVE_SETTINGS:
// fitting.fits.rgb_conductor.fit_rgb_conductor_coefficients, first-order
// CIEDE2000, no reweighting, at most 200 evaluations, no warm start, the
// float16 values rounded, not searched). That kind is a reflectance by
// construction: no [0, 1] rule to hold, no fallback.
//
// The start is the server's: per channel the linear-RGB fit of (n_c, k_c)
// from n = 0.2, 1, 3 (k from the reflectance nearest normal incidence in
// the lowest coating), the best start kept. Both solves run the
// trust-region iteration of live_trf.js; within n in [1e-3, 20] and k in
// [0, 50] (the server's bounds, which the optimum of a measured conductor
// lies well inside) a step outside is clipped. Coefficients flat
// (n_R, n_G, n_B, k_R, k_G, k_B).

import { trf } from "./live_trf.js";
import { de2000Weights, labAndJacobian, toHalf } from "./live_solve.js";

export const RGB_LIVE = Object.freeze({ maxNfev: 200, tol: 1e-10, startTol: 1e-10, nStarts: [0.2, 1.0, 3.0] });
const N_BOUNDS = [1e-3, 20], K_BOUNDS = [0, 50];
const INDEX_LIMITS = [1e-6, 1e8]; // fitting.domain.INDEX_LIMITS: the Fresnel's clamps
const TINY = 2.2250738585072014e-308;

// ------------------------------------------------------------ complex numbers [re, im]

const mul = ([a, b], [c, d]) => [a * c - b * d, a * d + b * c];
const div = ([a, b], [c, d]) => { const q = c * c + d * d; return [(a * c + b * d) / q, (b * c - a * d) / q]; };
const add = ([a, b], [c, d]) => [a + c, b + d];
const sub = ([a, b], [c, d]) => [a - c, b - d];
const abs2 = ([a, b]) => a * a + b * b;
/** The principal square root (numpy's). */
function csqrt([a, b]) {
  const r = Math.hypot(a, b);
  const re = Math.sqrt(Math.max(0, (r + a) / 2)), im = Math.sqrt(Math.max(0, (r - a) / 2));
  return [re, b < 0 || (b === 0 && Object.is(b, -0)) ? -im : im];
}
const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));

/**
 * The unpolarised Fresnel reflectance of a conductor (n + i k) under a
 * coating eta_i at mu = cos theta (fitting.optics.fresnel.fresnel_conductor,
 * its clamps) and its derivatives: {R, dn, dk} (fresnel_conductor_derivatives).
 */
export function fresnelConductor(mu, etaI, n, k) {
  const [lo, hi] = INDEX_LIMITS;
  const nIn = n >= lo && n <= hi, kIn = k >= 0 && k <= hi;
  mu = clamp(mu, 0, 1);
  n = clamp(n, lo, hi);
  k = clamp(k, 0, hi);
  etaI = clamp(etaI, lo, hi);
  const eta = [n / etaI, k / etaI], s = 1 - mu * mu;
  const eta2 = mul(eta, eta);
  const cosT = csqrt(sub([1, 0], div([s, 0], eta2)));
  const etaCos = mul(eta, cosT), etaMu = [eta[0] * mu, eta[1] * mu];
  const numS = sub([mu, 0], etaCos), denS = add([mu, 0], etaCos);
  const numP = sub(etaMu, cosT), denP = add(etaMu, cosT);
  const R = 0.5 * (abs2(numS) / Math.max(abs2(denS), TINY) + abs2(numP) / Math.max(abs2(denP), TINY));
  // r_s, r_p are analytic in eta: dR/d eta along 1 and i from D = conj(r_s) r_s' + conj(r_p) r_p'.
  const rs = div(numS, denS), rp = div(numP, denP);
  const dCos = div([s, 0], mul(mul(eta2, eta), cosT)); // d cos_t / d eta = s / (eta^3 cos_t)
  const dEtaCos = add(cosT, mul(eta, dCos));
  const dRs = div(mul([-2 * mu, 0], dEtaCos), mul(denS, denS));
  const dRp = div(sub([2 * mu * cosT[0], 2 * mu * cosT[1]], mul([2 * mu, 0], mul(eta, dCos))), mul(denP, denP));
  const D = add(mul([rs[0], -rs[1]], dRs), mul([rp[0], -rp[1]], dRp));
  // Where a clamp holds (R at 0 or 1, an index at its limits) or cos_t = 0 (k = 0 at the critical angle): 0.
  const inside = R > 0 && R < 1 && (cosT[0] !== 0 || cosT[1] !== 0) && Number.isFinite(D[0]) && Number.isFinite(D[1]);
  return { R: clamp(R, 0, 1), dn: inside && nIn ? D[0] / etaI : 0, dk: inside && kIn ? -D[1] / etaI : 0 };
}

/** The model at (mu, eta) arrays of flat n, k (6): reflectance (S x 3). */
export function rgbConductorValues(x, mu, eta) {
  return mu.map((m, s) => [0, 1, 2].map((c) => fresnelConductor(m, eta[s], x[c], x[3 + c]).R));
}

// ------------------------------------------------------------ the solves

const sqrtWeights = (S, weights) => Float64Array.from({ length: S }, (_, s) => Math.sqrt(weights ? weights[s] : 1));

/** The first-order CIEDE2000 residuals of the live problem (RGBConductorObjective "de2000") as trf's `fun`. */
function de2000Objective(target, mu, eta, weights) {
  const S = mu.length, w = sqrtWeights(S, weights);
  const ref = target.map((t) => labAndJacobian(t).lab);
  const A = ref.map(de2000Weights);
  return (x, withJ) => {
    const f = new Float64Array(3 * S), J = withJ ? new Float64Array(3 * S * 6) : null;
    for (let s = 0; s < S; s++) {
      const F = [0, 0, 0], dF = [[0, 0, 0], [0, 0, 0]];
      for (let c = 0; c < 3; c++) {
        const r = fresnelConductor(mu[s], eta[s], x[c], x[3 + c]);
        F[c] = r.R;
        dF[0][c] = r.dn;
        dF[1][c] = r.dk;
      }
      const { lab, J: dLab } = labAndJacobian(F);
      const d = [lab[0] - ref[s][0], lab[1] - ref[s][1], lab[2] - ref[s][2]];
      const As = A[s];
      for (let o = 0; o < 3; o++) {
        f[3 * s + o] = (As[o][0] * d[0] + As[o][1] * d[1] + As[o][2] * d[2]) * w[s];
        if (!withJ) continue;
        for (let c = 0; c < 3; c++) {
          const G = (As[o][0] * dLab[0][c] + As[o][1] * dLab[1][c] + As[o][2] * dLab[2][c]) * w[s];
          J[(3 * s + o) * 6 + c] = G * dF[0][c];
          J[(3 * s + o) * 6 + 3 + c] = G * dF[1][c];
        }
      }
    }
    return { f, J, zero: new Uint8Array(3 * S) };
  };
}

/** `fun` with x clipped into the bounds first (the server's solves stay inside them). */
const bounded = (fun, lower, upper) => (x, withJ) => fun(x.map((v, i) => clamp(v, lower[i], upper[i])), withJ);

/** Per channel the linear-RGB fit of (n_c, k_c) from a few starts of n, the best kept (rgb_conductor._initial_guess). */
export function initialGuess(target, mu, eta, weights = null, settings = RGB_LIVE) {
  const S = mu.length, w = sqrtWeights(S, weights);
  // The sample nearest normal incidence in the lowest coating (numpy lexsort((-mu, eta))[0]).
  let normal = 0;
  for (let s = 1; s < S; s++) {
    if (eta[s] < eta[normal] || (eta[s] === eta[normal] && mu[s] > mu[normal])) normal = s;
  }
  const eta0 = eta[normal], x0 = new Float64Array(6);
  for (let c = 0; c < 3; c++) {
    const F0 = clamp(target[normal][c], 0, 0.999);
    const fun = bounded((x, withJ) => {
      const f = new Float64Array(S), J = withJ ? new Float64Array(2 * S) : null;
      for (let s = 0; s < S; s++) {
        const r = fresnelConductor(mu[s], eta[s], x[0], x[1]);
        f[s] = (r.R - target[s][c]) * w[s];
        if (withJ) {
          J[2 * s] = r.dn * w[s];
          J[2 * s + 1] = r.dk * w[s];
        }
      }
      return { f, J, zero: new Uint8Array(S) };
    }, [N_BOUNDS[0], K_BOUNDS[0]], [N_BOUNDS[1], K_BOUNDS[1]]);
    let best = null;
    for (const n of settings.nStarts) {
      const k2 = (F0 * (n + eta0) ** 2 - (n - eta0) ** 2) / (1 - F0);
      const start = [clamp(n, ...N_BOUNDS), clamp(Math.sqrt(Math.max(k2, 0)), ...K_BOUNDS)];
      const fit = trf(fun, start, 2, settings.startTol, 200);
      if (best === null || fit.cost < best.cost) best = fit;
    }
    x0[c] = clamp(best.x[0], ...N_BOUNDS);
    x0[3 + c] = clamp(best.x[1], ...K_BOUNDS);
  }
  return x0;
}

/**
 * The live step of the conductor kind: `target` (S x 3 linear ACEScg),
 * `mu`, `eta` (S), `weights` (S, or null): {coefficients (6), coefficients16
 * (float16 values), bestEffort (false: in [0, 1] by construction), nfev, ms}.
 */
export function liveStepRGBConductor({ target, mu, eta, weights = null }, settings = RGB_LIVE) {
  const t0 = typeof performance === "undefined" ? Date.now() : performance.now();
  const lower = [...Array(3).fill(N_BOUNDS[0]), ...Array(3).fill(K_BOUNDS[0])];
  const upper = [...Array(3).fill(N_BOUNDS[1]), ...Array(3).fill(K_BOUNDS[1])];
  const start = initialGuess(target, mu, eta, weights, settings);
  const fun = bounded(de2000Objective(target, mu, eta, weights), lower, upper);
  const result = trf(fun, start, 6, settings.tol, settings.maxNfev);
  const coefficients = Array.from(result.x, (v, i) => clamp(v, lower[i], upper[i]));
  const t1 = typeof performance === "undefined" ? Date.now() : performance.now();
  return { coefficients, coefficients16: coefficients.map(toHalf), bestEffort: false, nfev: result.nfev, ms: t1 - t0 };
}
