// The trust-region least-squares iteration of the server's fits
// (fitting/numerics/trf.py trf_least_squares: scipy's "trf" without bounds,
// x_scale "jac", the exact subproblem by Cholesky factorisations, More
// 1977), step for step: the same radius rule, stopping tests and
// evaluation count, so that the page's live refit (live_solve.js) lands
// where the server's does. Pure; for 9 to 27 unknowns.

const EPS = 2.220446049250313e-16;

export const dot = (u, v) => { let s = 0; for (let i = 0; i < u.length; i++) s += u[i] * v[i]; return s; };
const norm = (v) => Math.sqrt(dot(v, v));

function normal({ J, zero, A: given, g: givenG }, f, n) {
  if (given) return { A: given, g: givenG }; // the normal equations, summed by `fun` itself
  const A = Array.from({ length: n }, () => new Float64Array(n)), g = new Float64Array(n);
  for (let r = 0; r < f.length; r++) {
    if (zero[r]) continue;
    const row = r * n, fr = f[r];
    for (let i = 0; i < n; i++) {
      const v = J[row + i];
      if (v === 0) continue;
      g[i] += v * fr;
      const Ai = A[i];
      for (let k = 0; k <= i; k++) Ai[k] += v * J[row + k];
    }
  }
  for (let i = 0; i < n; i++) for (let k = 0; k < i; k++) A[k][i] = A[i][k];
  return { A, g };
}

/** {pivots, L} of the Cholesky factor of A (lower, A = L L^T), or null when A is not positive definite. */
function factorOf(A) {
  const n = A.length, L = Array.from({ length: n }, () => new Float64Array(n));
  for (let i = 0; i < n; i++) {
    const Li = L[i];
    for (let k = 0; k <= i; k++) {
      const Lk = L[k];
      let s = A[i][k];
      for (let j = 0; j < k; j++) s -= Li[j] * Lk[j];
      if (i === k) {
        if (!(s > 0)) return null;
        Li[i] = Math.sqrt(s);
      } else Li[k] = s / Lk[k];
    }
  }
  return { pivots: L.map((row, i) => row[i]), L };
}

/** L^-1 v (forward substitution). */
function forward(L, v) {
  const n = v.length, y = new Float64Array(n);
  for (let i = 0; i < n; i++) {
    const Li = L[i];
    let s = v[i];
    for (let j = 0; j < i; j++) s -= Li[j] * y[j];
    y[i] = s / Li[i];
  }
  return y;
}

/** L^-T v (back substitution). */
function backward(L, v) {
  const n = v.length, z = new Float64Array(n);
  for (let i = n - 1; i >= 0; i--) {
    let s = v[i];
    for (let j = i + 1; j < n; j++) s -= L[j][i] * z[j];
    z[i] = s / L[i][i];
  }
  return z;
}

const mulVec = (M, v) => M.map((row) => dot(row, v));
const solveWith = (L, g) => backward(L, forward(L, g)).map((v) => -v); // -(L L^T)^-1 g
const shifted = (H, alpha) => H.map((row, i) => { const r = Float64Array.from(row); r[i] += alpha; return r; });

/** The trust-region step (fitting/numerics/trf.py _step): {p, alpha}. */
function step(H, g, Delta, alpha, rtol = 0.01, maxIter = 10) {
  let factor = factorOf(H);
  const fullRank = factor !== null && Math.min(...factor.pivots) > 1e-7 * Math.max(...factor.pivots);
  let alphaLower = 0;
  if (fullRank) {
    const p = solveWith(factor.L, g), pNorm = norm(p);
    if (pNorm <= Delta) return { p, alpha: 0 };
    const q = forward(factor.L, p);
    alphaLower = ((pNorm - Delta) * pNorm) / dot(q, q);
  }
  let alphaUpper = norm(g) / Delta;
  const trace = H.reduce((s, row, i) => s + row[i], 0);
  if (alpha === null || (!fullRank && alpha === 0)) alpha = Math.max(0.001 * alphaUpper, Math.sqrt(alphaLower * alphaUpper));
  for (let it = 0; it < maxIter; it++) {
    if (alpha < alphaLower || alpha > alphaUpper) alpha = Math.max(0.001 * alphaUpper, Math.sqrt(alphaLower * alphaUpper));
    factor = factorOf(shifted(H, alpha));
    if (factor === null) {
      alphaLower = alpha = Math.max(alpha * 10, EPS * trace, EPS);
      continue;
    }
    const p = solveWith(factor.L, g), pNorm = norm(p), phi = pNorm - Delta;
    const q = forward(factor.L, p), phiPrime = -dot(q, q) / pNorm;
    if (phi < 0) alphaUpper = alpha;
    const ratio = phi / phiPrime;
    alphaLower = Math.max(alphaLower, alpha - ratio);
    alpha -= ((phi + Delta) * ratio) / Delta;
    if (Math.abs(phi) < rtol * Delta) break;
  }
  factor = factorOf(shifted(H, alpha));
  while (factor === null) {
    alpha = Math.max(alpha * 10, EPS * trace, EPS);
    factor = factorOf(shifted(H, alpha));
  }
  const p = solveWith(factor.L, g), scale = Delta / norm(p);
  return { p: p.map((v) => v * scale), alpha };
}

/**
 * min 1/2 |f(x)|^2 from x0 by the server's trust-region iteration
 * (fitting.numerics.trf_least_squares), `fun(x, withJ)` -> {f (m), J (m x n
 * flat by rows, with withJ), zero (rows of J all zero)}: {x, cost, nfev, njev, status}
 * (status 0: out of evaluations, -1: a Jacobian not finite, 1-4: gtol,
 * ftol, xtol, both).
 */
export function trf(fun, x0, n, tol = 1e-10, maxNfev = 4) {
  let x = Float64Array.from(x0);
  let at = fun(x, true);
  let nfev = 1, njev = 1, cost = 0.5 * dot(at.f, at.f);
  let { A, g } = normal(at, at.f, n);
  let scaleInv = A.map((row, i) => Math.sqrt(row[i]) || 1);
  let Delta = norm(x.map((v, i) => v * scaleInv[i])) || 1;
  let alpha = 0, status = null;
  for (;;) {
    if (!Number.isFinite(A.reduce((s, row) => s + row.reduce((t, v) => t + v, 0), 0) + g.reduce((s, v) => s + v, 0))) {
      status = -1;
      break;
    }
    if (Math.max(...g.map(Math.abs)) < tol) status = 1;
    if (status !== null || nfev === maxNfev) break;
    const d = scaleInv.map((v) => 1 / v);
    const H = A.map((row, i) => row.map((v, k) => v * d[i] * d[k])), gh = g.map((v, i) => v * d[i]);
    let actual = -1, xNew = null, fNew = null, costNew = 0;
    while (actual <= 0 && nfev < maxNfev) {
      const taken = step(H, gh, Delta, alpha);
      alpha = taken.alpha;
      const ph = taken.p;
      const Hp = mulVec(H, ph);
      const predicted = -(0.5 * dot(ph, Hp) + dot(gh, ph));
      const s = ph.map((v, i) => v * d[i]);
      xNew = x.map((v, i) => v + s[i]);
      fNew = fun(xNew, false).f;
      nfev += 1;
      const phNorm = norm(ph);
      costNew = 0.5 * dot(fNew, fNew);
      if (!Number.isFinite(costNew)) {
        Delta = 0.25 * phNorm;
        continue;
      }
      actual = cost - costNew;
      const ratio = predicted > 0 ? actual / predicted : predicted === 0 && actual === 0 ? 1 : 0;
      let DeltaNew = Delta;
      if (ratio < 0.25) DeltaNew = 0.25 * phNorm;
      else if (ratio > 0.75 && phNorm > 0.95 * Delta) DeltaNew = 2 * Delta;
      const ftolOk = actual < tol * cost && ratio > 0.25;
      const xtolOk = norm(s) < tol * (tol + norm(x));
      if (ftolOk || xtolOk) {
        status = ftolOk && xtolOk ? 4 : ftolOk ? 2 : 3;
        break;
      }
      alpha *= Delta / DeltaNew;
      Delta = DeltaNew;
    }
    if (actual > 0) {
      x = xNew;
      cost = costNew;
      at = fun(x, true);
      njev += 1;
      ({ A, g } = normal(at, fNew, n));
      scaleInv = scaleInv.map((v, i) => Math.max(Math.sqrt(A[i][i]), v));
    }
  }
  return { x, cost, nfev, njev, status: status ?? 0 };
}
