// The live refit in the page: the server's live step (fitting/fits/curves.py
// fit_curves with LIVE_SETTINGS, started from the fit on screen) mirrored
// for the coated-conductor kind, so that a drag is answered without a
// request. Pure functions, no DOM: run in a module worker (live_worker.js)
// and by node --test against the Python step (tests/static/js/live_solve.test.mjs).
//
// The objective (fitting/fits/objective.py Problem, "de2000"):
//   min_C 1/2 sum_s |A_s (Lab(M(mu_s, eta_s; C)) - Lab(T_s))|^2
//         + 1/2 sum_k,c (w (min(F_kc, 0) + max(F_kc - 1, 0)))^2
// with M Eq. 1 of the model (fitting/models/coated_conductor.py), A_s the
// first-order CIEDE2000 metric at the target (fitting/colour/delta_e.py
// de2000_weights), and the hinge residuals at a check grid (curves_score.py
// check_grid, weight w), solved by the server's trust-region iteration
// (live_trf.js) with the analytic Jacobian.
//
// The in-range rule (curves_steps.py in_range_fit/held_in_range): while the float16 fit
// leaves [0, 1] on the scoring grid, the penalty is made ten times stiffer
// (twice at most, within the evaluation budget) with the points where it
// leaves added; a fit still outside gets its shape term shrunk channel by
// channel (curves_range.py in_range_fallback). The server also asks an
// interval proof over the whole domain; the page checks the grid only, and
// the server's full refit (with the proof) replaces the live fit on release.

import { dot, trf } from "./live_trf.js";

export const ALPHA_MIN = 1e-3;
export const LIVE = Object.freeze({
  maxNfev: 4, rangeWeight: 300, checkSamples: [10, 4], maxEvaluations: 24, muSamples: 12, etaSamples: 7,
});
const SCORE_GRID = [46, 31];
const RANGE_TOLERANCE = 1e-4;
const SHAPE_SCALES = [0.9, 0.75, 0.5, 0.25, 0.0];
const MIN_ESCALATION_NFEV = 10;
const BOUND = [16, 64, 256];

// ACEScg to XYZ and the ACES white (fitting/colour/colorimetry.py _matrices).
const M_XYZ = [
  [0.6624541811085055, 0.13400420645643313, 0.15618768700490773],
  [0.2722287167809146, 0.6740817658111483, 0.05368951740793703],
  [-0.005574649490394109, 0.004060733528982825, 1.010339100312997],
];
const XYZ_N = [0.9526460745698464, 1.0, 1.0088251843515856];
const MN = M_XYZ.map((row, i) => row.map((v) => v / XYZ_N[i]));
const DELTA = 6 / 29, DELTA3 = DELTA ** 3;

// ------------------------------------------------------------ grids

/** cos theta of an angle in degrees, exactly 0 at 90 (fitting.fits.curves_score.angle_mu). */
export const angleMu = (deg) => (deg === 90 ? 0 : Math.cos((deg * Math.PI) / 180));

/** numpy's linspace(lo, hi, n). */
export function linspace(lo, hi, n) {
  if (n === 1) return [lo];
  const step = (hi - lo) / (n - 1);
  return Array.from({ length: n }, (_, i) => (i === n - 1 ? hi : lo + i * step));
}

/** The [0, 1] check grid (curves_score.check_grid): {mu, eta}, eta_i rows outer, angles inner. */
export function checkGrid([lo, hi], angles, rows) {
  const half = Array.from({ length: 20 }, (_, i) => 80 + 0.5 * i);
  const theta = [...new Set([...linspace(0, 90, angles), ...half])].sort((a, b) => a - b);
  const etas = hi > lo ? linspace(lo, hi, rows) : [lo];
  const mu = [], eta = [];
  for (const e of etas) for (const t of theta) { mu.push(angleMu(t)); eta.push(e); }
  return { mu, eta };
}

// ------------------------------------------------------------ float16

/** Round to the nearest float16 value, ties to even (numpy's float64 to float16). */
export function toHalf(x) {
  const a = Math.abs(x);
  if (a === 0 || !Number.isFinite(x)) return x;
  if (a >= 65520) return Math.sign(x) * Infinity;
  let e = Math.floor(Math.log2(a));
  if (2 ** e > a) e -= 1;
  else if (2 ** (e + 1) <= a) e += 1;
  const q = 2 ** (Math.max(e, -14) - 10);
  const m = a / q, f = Math.floor(m), rest = m - f;
  const r = rest > 0.5 ? f + 1 : rest < 0.5 ? f : f % 2 ? f + 1 : f;
  return Math.sign(x) * r * q;
}

// ------------------------------------------------------------ colour

/** Lab of linear ACEScg (ACES white) and dLab/dRGB (3 x 3), the CIE formula's linear segment below delta^3. */
export function labAndJacobian(rgb) {
  const f = [0, 0, 0], df = [0, 0, 0];
  for (let i = 0; i < 3; i++) {
    const X = MN[i][0] * rgb[0] + MN[i][1] * rgb[1] + MN[i][2] * rgb[2];
    if (X > DELTA3) {
      const root = Math.cbrt(X);
      f[i] = root;
      df[i] = 1 / (3 * root * root);
    } else {
      f[i] = X / (3 * DELTA * DELTA) + 4 / 29;
      df[i] = 1 / (3 * DELTA * DELTA);
    }
  }
  const lab = [116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])];
  const J = [0, 1, 2].map((j) => [
    116 * df[1] * MN[1][j], 500 * (df[0] * MN[0][j] - df[1] * MN[1][j]), 200 * (df[1] * MN[1][j] - df[2] * MN[2][j]),
  ]);
  return { lab, J: [0, 1, 2].map((o) => [0, 1, 2].map((j) => J[j][o])) };
}

const rad = (deg) => (deg * Math.PI) / 180;

/** The first-order CIEDE2000 map A (3 x 3) at a reference Lab (fitting.colour.delta_e.de2000_weights). */
export function de2000Weights([L, a, b]) {
  const C = Math.hypot(a, b), C7 = C ** 7, P7 = 25 ** 7;
  const G = 0.5 * (1 - Math.sqrt(C7 / (C7 + P7)));
  const a1 = (1 + G) * a, C1 = Math.hypot(a1, b);
  const hDeg = (((Math.atan2(b, a1) * 180) / Math.PI) % 360 + 360) % 360;
  const safe = C1 > 1e-9;
  const cosH = safe ? a1 / C1 : 1, sinH = safe ? b / C1 : 0;
  const SL = 1 + (0.015 * (L - 50) ** 2) / Math.sqrt(20 + (L - 50) ** 2);
  const SC = 1 + 0.045 * C1;
  const T = 1 - 0.17 * Math.cos(rad(hDeg - 30)) + 0.24 * Math.cos(rad(2 * hDeg))
    + 0.32 * Math.cos(rad(3 * hDeg + 6)) - 0.2 * Math.cos(rad(4 * hDeg - 63));
  const SH = 1 + 0.015 * C1 * T;
  const C17 = C1 ** 7;
  const RT = -Math.sin(rad(60 * Math.exp(-(((hDeg - 275) / 25) ** 2)))) * 2 * Math.sqrt(C17 / (C17 + P7));
  const dC = [0, (1 + G) * cosH, sinH], dH = [0, -(1 + G) * sinH, cosH];
  const k = Math.sqrt(Math.min(1, Math.max(0, 1 - RT * RT / 4)));
  return [[1 / SL, 0, 0], dC.map((v, j) => v / SC + (RT / 2) * dH[j] / SH), dH.map((v) => (k * v) / SH)];
}

// ------------------------------------------------------------ the problem

/** The powers 1, t, t^2 (first d1) of the normalised coating index (coated_conductor.normalised_eta_i). */
function powersAt(eta, [lo, hi], d1) {
  const t = hi <= lo ? 0 : Math.min(1, Math.max(0, (eta - lo) / (hi - lo)));
  return [1, t, t * t].slice(0, d1);
}

/**
 * The live problem: `target` (S x 3 linear ACEScg), `mu`, `eta` (S),
 * `range` [lo, hi], `degree`, `weights` (S, or null), the check points
 * {mu, eta} and weight. The samples' geometry, the target's Lab and metric
 * kept in typed arrays (a solve evaluates them a few thousand times);
 * `samples`, another problem's of the same target, reused as they are.
 */
export function makeProblem({ target, mu, eta, range, degree, weights = null, check, checkWeight, samples = null }) {
  const d1 = degree + 1;
  if (samples) return { n: 9 * d1, d1, range, samples, checks: geometry(check.mu, check.eta, range, d1), checkWeight };
  samples = geometry(mu, eta, range, d1);
  const count = samples.count;
  samples.lab = new Float64Array(3 * count);
  samples.A = new Float64Array(9 * count);
  samples.sw = new Float64Array(count);
  for (let s = 0; s < count; s++) {
    const { lab } = labAndJacobian(target[s]);
    samples.lab.set(lab, 3 * s);
    samples.A.set(de2000Weights(lab).flat(), 9 * s);
    samples.sw[s] = weights ? Math.sqrt(weights[s]) : 1;
  }
  return { n: 9 * d1, d1, range, samples, checks: geometry(check.mu, check.eta, range, d1), checkWeight };
}

/**
 * The model's value at point k of `geo` in channel c (Eq. 1: F0 + (1 - F0)
 * (1 - mu)^5 - a mu (1 - mu)^alpha), and with `dP` its derivatives by F0,
 * a, alpha into dP[o], dP[o + 1], dP[o + 2]. x^alpha as exp(alpha log x).
 */
function channelAt(geo, k, x, d1, c, dP, o) {
  const T = geo.T, t = k * d1;
  let F0 = 0, a = 0, alpha = 0;
  for (let j = 0; j < d1; j++) {
    const tj = T[t + j];
    F0 += tj * x[c * d1 + j];
    a += tj * x[(3 + c) * d1 + j];
    alpha += tj * x[(6 + c) * d1 + j];
  }
  const muXAlpha = geo.x[k] > 0 ? geo.mu[k] * Math.exp(Math.max(alpha, ALPHA_MIN) * geo.logx[k]) : 0;
  if (dP) {
    dP[o] = 1 - geo.x5[k];
    dP[o + 1] = -muXAlpha;
    dP[o + 2] = alpha > ALPHA_MIN ? -a * muXAlpha * geo.logx[k] : 0;
  }
  return F0 + (1 - F0) * geo.x5[k] - a * muXAlpha;
}

const F = new Float64Array(3), DP = new Float64Array(9), LAB = new Float64Array(3), DLAB = new Float64Array(9);

/** Lab of linear ACEScg into LAB, dLab_o/dRGB_j into DLAB[3 o + j] (labAndJacobian, allocation free). */
function labInto(rgb) {
  let f0 = 0, f1 = 0, f2 = 0, df0 = 0, df1 = 0, df2 = 0;
  for (let i = 0; i < 3; i++) {
    const X = MN[i][0] * rgb[0] + MN[i][1] * rgb[1] + MN[i][2] * rgb[2];
    let fi, dfi;
    if (X > DELTA3) {
      const root = Math.cbrt(X);
      fi = root;
      dfi = 1 / (3 * root * root);
    } else {
      fi = X / (3 * DELTA * DELTA) + 4 / 29;
      dfi = 1 / (3 * DELTA * DELTA);
    }
    if (i === 0) { f0 = fi; df0 = dfi; } else if (i === 1) { f1 = fi; df1 = dfi; } else { f2 = fi; df2 = dfi; }
  }
  LAB[0] = 116 * f1 - 16;
  LAB[1] = 500 * (f0 - f1);
  LAB[2] = 200 * (f1 - f2);
  for (let j = 0; j < 3; j++) {
    DLAB[j] = 116 * df1 * MN[1][j];
    DLAB[3 + j] = 500 * (df0 * MN[0][j] - df1 * MN[1][j]);
    DLAB[6 + j] = 200 * (df1 * MN[1][j] - df2 * MN[2][j]);
  }
}

/**
 * Residuals f (m) at x and, with `withJ`, the normal equations of the
 * Jacobian J (m x n): A = J^T J (n rows of n) and g = J^T f, J itself
 * never formed. A sample's three rows of J are u_o (x) T, u_o over the nine
 * (parameter, channel) pairs and T the powers of t at its eta_i: the
 * samples' sum_o u_o u_o^T and u_o f_o are summed per eta_i row first, then
 * spread over the powers of t once a row.
 */
export function evaluate(problem, x, withJ = true) {
  const { n, d1, samples, checks, checkWeight } = problem;
  const m = 3 * (samples.count + checks.count), f = new Float64Array(m);
  const N = withJ ? new Float64Array(n * n) : null, g = withJ ? new Float64Array(n) : null;
  const dP = withJ ? DP : null, { lab: labT, A: As, sw: sws } = samples;
  const BR = withJ ? new Float64Array(81 * samples.rows) : null, GR = withJ ? new Float64Array(9 * samples.rows) : null;
  let r = 0;
  for (let s = 0; s < samples.count; s++) {
    for (let c = 0; c < 3; c++) F[c] = channelAt(samples, s, x, d1, c, dP, 3 * c);
    labInto(F);
    const d0 = LAB[0] - labT[3 * s], d1_ = LAB[1] - labT[3 * s + 1], d2 = LAB[2] - labT[3 * s + 2], sw = sws[s];
    for (let o = 0; o < 3; o++, r++) {
      const a = 9 * s + 3 * o, A0 = As[a], A1 = As[a + 1], A2 = As[a + 2];
      f[r] = sw * (A0 * d0 + A1 * d1_ + A2 * d2);
      if (!withJ) continue;
      for (let c = 0; c < 3; c++) {
        const G = sw * (A0 * DLAB[c] + A1 * DLAB[3 + c] + A2 * DLAB[6 + c]);
        for (let p = 0; p < 3; p++) U[9 * o + p * 3 + c] = G * DP[3 * c + p];
      }
    }
    if (withJ) addSample(BR, GR, U, f, r - 3, samples.row[s]);
  }
  if (withJ) spreadRows(N, g, BR, GR, samples, d1, n);
  for (let k = 0; k < checks.count; k++) {
    for (let c = 0; c < 3; c++, r++) {
      const value = channelAt(checks, k, x, d1, c, dP, 0);
      f[r] = checkWeight * (Math.min(value, 0) + Math.max(value - 1, 0));
      if (!withJ || !(value < 0 || value > 1)) continue;
      for (let p = 0; p < 3; p++) U[p] = checkWeight * DP[p];
      addHinge(N, g, U, f[r], checks.T, k * d1, c, d1, n);
    }
  }
  if (!withJ) return { f };
  const A = Array.from({ length: n }, (_, i) => N.subarray(i * n, (i + 1) * n));
  for (let i = 0; i < n; i++) for (let k = 0; k < i; k++) A[k][i] = A[i][k];
  return { f, A, g };
}

const U = new Float64Array(27);

/** A sample's sum_o u_o u_o^T (lower triangle) and u_o f_o (u in U[9 o + q], q = 3 p + c) into its row's sums. */
function addSample(BR, GR, U, f, r, row) {
  const b = 81 * row, h = 9 * row;
  for (let q = 0; q < 9; q++) {
    for (let w = 0; w <= q; w++) BR[b + 9 * q + w] += U[q] * U[w] + U[9 + q] * U[9 + w] + U[18 + q] * U[18 + w];
    GR[h + q] += U[q] * f[r] + U[9 + q] * f[r + 1] + U[18 + q] * f[r + 2];
  }
}

/** Each eta_i row's sums spread over its powers of t (B (x) T T^T, G (x) T) into N's lower triangle and g. */
function spreadRows(N, g, BR, GR, samples, d1, n) {
  for (let row = 0; row < samples.rows; row++) {
    const t = samples.rowStart[row] * d1, T = samples.T, b = 81 * row;
    for (let q = 0; q < 9; q++) {
      for (let j = 0; j < d1; j++) {
        const i = q * d1 + j, Tj = T[t + j], at = i * n;
        g[i] += GR[9 * row + q] * Tj;
        for (let w = 0; w <= q; w++) {
          const v = BR[b + 9 * q + w] * Tj, top = w === q ? j : d1 - 1;
          for (let jj = 0; jj <= top; jj++) N[at + w * d1 + jj] += v * T[t + jj];
        }
      }
    }
  }
}

/** An active hinge's row of J (U[p] T at the columns of channel c) into N's lower triangle and g. */
function addHinge(N, g, U, fr, T, t, c, d1, n) {
  for (let p = 0; p < 3; p++) {
    for (let j = 0; j < d1; j++) {
      const i = (p * 3 + c) * d1 + j, v = U[p] * T[t + j], row = i * n;
      g[i] += v * fr;
      for (let pp = 0; pp <= p; pp++) {
        const top = pp === p ? j : d1 - 1;
        for (let jj = 0; jj <= top; jj++) N[row + (pp * 3 + c) * d1 + jj] += v * U[pp] * T[t + jj];
      }
    }
  }
}

/** The trust-region solve of the live problem from x0 (live_trf.js trf): {x, cost, nfev, njev, status}. */
export function solveLive(problem, x0, tol = 1e-10, maxNfev = 4) {
  return trf((x, withJ) => evaluate(problem, x, withJ), x0, problem.n, tol, maxNfev);
}

// ------------------------------------------------------------ the live step

/** Coefficient bounds (objective.coefficient_bounds) of a flat x of degree d1 - 1. */
function clipToBounds(x, d1) {
  return Array.from(x, (v, i) => {
    const p = Math.floor(i / (3 * d1)), lower = p === 2 && i % d1 === 0 ? ALPHA_MIN : -BOUND[p];
    return Math.min(BOUND[p], Math.max(lower, v));
  });
}

/** The samples' geometry at (mu, eta) arrays: clamped mu, x = 1 - mu, x^5, log x, the powers of t (d1 a point), typed; their eta_i rows. */
function geometry(mu, eta, range, d1) {
  const count = mu.length, g = { count, mu: new Float64Array(count), x: new Float64Array(count),
    x5: new Float64Array(count), logx: new Float64Array(count), T: new Float64Array(count * d1),
    row: new Int32Array(count), rowStart: [] }; // the points' eta_i rows (same eta_i, same powers of t)
  const rows = new Map();
  for (let s = 0; s < count; s++) {
    const mm = Math.min(1, Math.max(0, mu[s])), x = 1 - mm;
    g.mu[s] = mm;
    g.x[s] = x;
    g.x5[s] = x ** 5;
    g.logx[s] = x > 0 ? Math.log(x) : 0;
    g.T.set(powersAt(eta[s], range, d1), s * d1);
    if (!rows.has(eta[s])) {
      rows.set(eta[s], rows.size);
      g.rowStart.push(s);
    }
    g.row[s] = rows.get(eta[s]);
  }
  g.rows = rows.size;
  return g;
}

const GRIDS = new Map(); // the scoring grid's geometry, per domain and degree (a drag keeps one)

function scoringGrid(range, d1) {
  const name = `${range[0]} ${range[1]} ${d1}`;
  if (!GRIDS.has(name)) {
    const grid = checkGrid(range, ...SCORE_GRID);
    if (GRIDS.size > 8) GRIDS.clear();
    GRIDS.set(name, { ...grid, geo: geometry(grid.mu, grid.eta, range, d1) });
  }
  return GRIDS.get(name);
}

/** The model of flat coefficients at (mu, eta) arrays: channel values, (S x 3). */
export function modelValues(x, mu, eta, range, d1) {
  const geo = geometry(mu, eta, range, d1);
  return Array.from(mu, (_, s) => [0, 1, 2].map((c) => channelAt(geo, s, x, d1, c, null, 0)));
}

/**
 * Scoring-grid points and channels where float16 coefficients leave [0, 1]
 * (curves_range.outside_range): a Uint8Array, 3 per point (bit set:
 * outside), or null when none is.
 */
function outsideMask(C16, range, d1, grid) {
  const geo = grid.geo;
  let mask = null;
  for (let k = 0; k < geo.count; k++) {
    for (let c = 0; c < 3; c++) {
      const v = channelAt(geo, k, C16, d1, c, null, 0);
      if (v < -RANGE_TOLERANCE || v > 1 + RANGE_TOLERANCE) {
        mask ??= new Uint8Array(3 * geo.count);
        mask[3 * k + c] = 1;
      }
    }
  }
  return mask;
}

const channelOutside = (mask, c) => mask !== null && mask.some((v, i) => v && i % 3 === c);
const pointOutside = (mask, k) => mask[3 * k] || mask[3 * k + 1] || mask[3 * k + 2];

/** Float16 coefficients in [0, 1] on the scoring grid, the shape term shrunk per channel (in_range_fallback, grid part). */
function inRangeFallback(C16, range, d1, grid) {
  const C = Float64Array.from(C16);
  const half = () => Array.from(C, toHalf);
  const first = outsideMask(half(), range, d1, grid);
  const bad = [0, 1, 2].map((c) => channelOutside(first, c));
  const rows = range[1] > range[0] ? linspace(range[0], range[1], SCORE_GRID[1]) : [range[0]];
  for (let c = 0; c < 3; c++) {
    if (!bad[c]) continue;
    const F0 = rows.map((e) => powersAt(e, range, d1).reduce((s, t, j) => s + t * C[c * d1 + j], 0));
    if (Math.min(...F0) < 0 || Math.max(...F0) > 1) {
      for (let j = 0; j < d1; j++) C[c * d1 + j] = 0;
      C[c * d1] = Math.min(1, Math.max(0, F0.reduce((s, v) => s + v, 0) / F0.length));
    }
    const a = Array.from({ length: d1 }, (_, j) => C[(3 + c) * d1 + j]);
    for (const scale of SHAPE_SCALES) {
      a.forEach((v, j) => { C[(3 + c) * d1 + j] = scale * v; });
      if (!channelOutside(outsideMask(half(), range, d1, grid), c)) break;
    }
  }
  return half();
}

/**
 * The live step of `input` ({target, mu, eta, range, degree, weights, start}:
 * start the flat float16 coefficients on screen, 9 (degree + 1) values in
 * the order coefficients[p][c][j]): {coefficients (float64), coefficients16,
 * inRange, bestEffort, nfev, njev, ms}.
 */
export function liveStep(input, settings = LIVE) {
  const t0 = typeof performance === "undefined" ? Date.now() : performance.now();
  const { range, degree } = input;
  const d1 = degree + 1;
  const grid = scoringGrid(range, d1);
  const baseCheck = checkGrid(range, ...settings.checkSamples);
  let left = settings.maxEvaluations, cut = false, nfevAll = 0, njevAll = 0;
  const samples = makeProblem({ ...input, check: { mu: [], eta: [] }, checkWeight: 0 }).samples; // kept between rounds
  const solveFrom = (start, weight, check) => {
    const maxNfev = Math.min(settings.maxNfev, Math.max(1, Math.floor(left / 2)));
    const problem = makeProblem({ ...input, check, checkWeight: weight, samples });
    const result = solveLive(problem, clipToBounds(start, d1), 1e-10, maxNfev);
    left -= result.nfev + result.njev;
    nfevAll += result.nfev; njevAll += result.njev;
    if (maxNfev < settings.maxNfev && result.status === 0) cut = true;
    return clipToBounds(result.x, d1); // the server solves again with bounds when the optimum leaves its box
  };
  const outside = (x) => outsideMask(Array.from(x, toHalf), range, d1, grid);
  let weight = settings.rangeWeight, check = baseCheck;
  let x = solveFrom(input.start, weight, check);
  for (let round = 0; round < 2; round++) {
    const mask = outside(x);
    if (mask === null) break;
    if (left < MIN_ESCALATION_NFEV) { cut = true; break; }
    const extra = { mu: [], eta: [] };
    grid.mu.forEach((m, k) => { if (pointOutside(mask, k)) { extra.mu.push(m); extra.eta.push(grid.eta[k]); } });
    check = { mu: [...check.mu, ...extra.mu], eta: [...check.eta, ...extra.eta] };
    weight *= 10;
    x = solveFrom(x, weight, check);
  }
  let C16 = Array.from(x, toHalf), bestEffort = cut;
  if (outside(x) !== null) {
    C16 = inRangeFallback(C16, range, d1, grid);
    bestEffort = true;
    // The closer to the edit (by the objective's data term) of the fallback and the fit on screen.
    const data = (c) => {
      const { f } = evaluate(makeProblem({ ...input, check: { mu: [], eta: [] }, checkWeight: 1, samples }), c, false);
      return dot(f, f);
    };
    const onScreen = Array.from(input.start, toHalf);
    if (outside(onScreen) === null && data(onScreen) < data(C16)) C16 = onScreen;
  }
  const t1 = typeof performance === "undefined" ? Date.now() : performance.now();
  return { coefficients: Array.from(x), coefficients16: C16, bestEffort, nfev: nfevAll, njev: njevAll, ms: t1 - t0 };
}

// ------------------------------------------------------------ the live target

function smoothstep(v) {
  const x = Math.min(1, Math.max(0, v));
  return x * x * (3 - 2 * x);
}

/** The weight of each edit at `eta` (fitting.fits.curves_base.blend_weights). */
export function blendWeights(eta, edits, width) {
  const order = edits.map((e, k) => [e, k]).sort((p, q) => p[0] - q[0]);
  const e = order.map((p) => p[0]), W = new Array(e.length).fill(0);
  if (eta <= e[0]) W[0] = smoothstep(1 - (e[0] - eta) / width);
  if (eta >= e[e.length - 1]) W[e.length - 1] = smoothstep(1 - (eta - e[e.length - 1]) / width);
  for (let k = 0; k < e.length - 1; k++) {
    if (eta >= e[k] && eta < e[k + 1]) {
      const s = smoothstep((eta - e[k]) / (e[k + 1] - e[k]));
      W[k] = 1 - s;
      W[k + 1] = s;
    }
  }
  const out = new Array(e.length);
  order.forEach(([, k], i) => { out[k] = W[i]; });
  return out;
}

/** A curve given at angles (degrees) interpolated linearly in cos theta, held flat past its ends (RGBCurve.sampled). */
export function sampledCurve(angleDeg, rgb, mu) {
  const pts = angleDeg.map((a, i) => [angleMu(a), rgb[i]]).sort((p, q) => p[0] - q[0]);
  return mu.map((m) => {
    if (m <= pts[0][0]) return [...pts[0][1]];
    if (m >= pts[pts.length - 1][0]) return [...pts[pts.length - 1][1]];
    let i = 1;
    while (pts[i][0] < m) i++;
    const [m0, c0] = pts[i - 1], [m1, c1] = pts[i], u = (m - m0) / (m1 - m0);
    return c0.map((v, c) => v + (c1[c] - v) * u);
  });
}

/**
 * The live problem's samples and target (fit_curves with a base): angles
 * evenly over [0, 90] (LIVE.muSamples) at LIVE.etaSamples rows over the
 * domain plus each edited row, the base blended with the edits
 * (curves_base.edited_target) and clipped to [0, 1]. `edits`: [{eta_i,
 * angle_deg, rgb}]; `baseAt(eta)`: the base's reflectance at the angles
 * `muRow` (muSamples x 3) for a row or an edited eta_i.
 */
export function liveTarget(edits, baseAt, range, blendWidth = 0.5, settings = LIVE) {
  const [lo, hi] = range;
  const muRow = linspace(0, 90, settings.muSamples).map(angleMu);
  const edited = edits.map((c) => c.eta_i);
  const rows = (hi > lo ? linspace(lo, hi, settings.etaSamples) : [lo])
    .filter((r) => edited.every((e) => Math.abs(r - e) > 1e-6));
  const all = [...rows, ...edited].sort((a, b) => a - b);
  const curves = edits.map((c) => sampledCurve(c.angle_deg, c.rgb, muRow));
  const baseEdited = edited.map((e) => baseAt(e));
  const target = [], mu = [], eta = [];
  for (const r of all) {
    const B = baseAt(r), W = blendWeights(r, edited, blendWidth);
    muRow.forEach((m, i) => {
      const T = [0, 1, 2].map((c) => W.reduce((s, w, k) => s + w * (curves[k][i][c] - baseEdited[k][i][c]), B[i][c]));
      target.push(T.map((v) => Math.min(1, Math.max(0, v))));
      mu.push(m);
      eta.push(r);
    });
  }
  return { target, mu, eta, muRow, rows: all };
}
