// The editor's live refits in the page: while a pointer holds a point, each
// move is refitted by the module worker (live_worker.js, the server's live
// step mirrored in live_solve.js) from the fit on screen, with no request;
// the full refit on release (refit.js) replaces the result. One solve in
// flight at a time; a move made meanwhile waits, and only the latest is
// solved (as refit.js coalesces requests).
//
// The live target needs the base's reflectance at the live step's angles on
// its rows (and at each edited eta_i): asked for once per base and eta_i
// (GET /fits/{id}/curves?samples=12, `rowsOf`) and kept. Until they are in,
// or for a kind the page has no solver of (kinds.js liveSolver: the name
// the server gives the kind's, looked up in SOLVERS), `ready` says no and
// the editor asks the server's live step instead.

import { modelKind } from "../kinds.js";
import { rgbConductorValues } from "./live_rgb_conductor.js";
import { LIVE, linspace, modelValues } from "./live_solve.js";

const BLEND_WIDTH = 0.5; // fitting.fits.curves_settings.CurveFitSettings.blend_width (the editor sends none)
const rowKey = (eta) => Number(eta).toFixed(6);
const now = () => (typeof performance === "undefined" ? Date.now() : performance.now());
const origin = () => (typeof performance === "undefined" ? 0 : performance.timeOrigin);

/**
 * The page's live solvers (live_worker.js solves by the same names), by the
 * name the server gives a kind's (kinds.js liveSolver): the degree in eta_i
 * of a live step over a domain, and the model of flat coefficients at (mu,
 * eta) arrays (S x 3).
 */
export const SOLVERS = Object.freeze({
  polynomial: { degree: ([lo, hi]) => (hi > lo ? 2 : 0), values: modelValues },
  "exact-fresnel": { degree: () => 0, values: (x, mu, eta) => rgbConductorValues(x, mu, eta) },
});

const POLYNOMIAL = { parameters: ["F0", "a", "alpha"], maxDegree: 2 }; // the default kind's shape (the tests' form)

/**
 * A fit's coefficients of a kind's `parameters`, flat (p, c, j) at `d1`
 * powers, or (p, c) for a kind of `maxDegree` 0 (one number a channel).
 */
export function flatCoefficients(C, d1, { parameters, maxDegree } = POLYNOMIAL) {
  const out = [];
  for (const p of parameters) {
    for (let c = 0; c < 3; c++) {
      if (maxDegree === 0) out.push(C[p][c]);
      else for (let j = 0; j < d1; j++) out.push(C[p][c][j] ?? 0);
    }
  }
  return out;
}

/** Flat coefficients back to the API's form (flatCoefficients' inverse). */
export function nestedCoefficients(x, d1, { parameters, maxDegree } = POLYNOMIAL) {
  const C = {};
  parameters.forEach((p, i) => {
    C[p] = [0, 1, 2].map((c) => (maxDegree === 0 ? x[i * 3 + c] : x.slice((i * 3 + c) * d1, (i * 3 + c + 1) * d1)));
  });
  return C;
}

/** The eta_i rows of the live target over a domain (curves_problem.py base_samples: etaSamples evenly over it). */
export const liveRows = ([lo, hi]) => (hi > lo ? linspace(lo, hi, LIVE.etaSamples) : [lo]);

export class LiveRefit {
  /**
   * io: rowsOf(base, eta) -> Promise of the base's rgb rows (LIVE.muSamples x 3) at eta;
   * show({fit, model, job}): an in-page fit to put on screen; worker: a Worker (live_worker.js).
   */
  constructor(io) {
    this.io = io;
    this.worker = io.worker;
    this.worker.onmessage = ({ data }) => this.#answered(data);
    this.rows = new Map(); // key(eta) -> rows, of `this.base`
    this.base = null;
    this.seq = 0;
    this.inFlight = null;
    this.wanted = null;
  }

  /** Whether the page solves live refits of `base` (its kind, its rows in). */
  supports(base) {
    try {
      return Object.hasOwn(SOLVERS, modelKind(base).liveSolver ?? "") && base.eta_i_range !== undefined;
    } catch {
      return false;
    }
  }

  /** Ask for the base's rows (its live rows and the eta_i given) of `base`, once each. */
  prepare(base, etas = []) {
    if (!this.supports(base)) return;
    if (this.base !== base) {
      this.base = base;
      this.rows = new Map();
      this.wanted = null;
    }
    for (const eta of [...liveRows(base.eta_i_range), ...etas]) {
      const name = rowKey(eta);
      if (this.rows.has(name)) continue;
      this.rows.set(name, null);
      this.io.rowsOf(base, Number(eta)).then((rows) => {
        if (this.base === base) this.rows.set(name, rows);
      }, () => this.rows.delete(name));
    }
  }

  /** Whether a live refit of `edits` ({eta key: rgb}) on `base` can be solved here now. */
  ready(base, edits) {
    if (this.base !== base || !this.supports(base)) return false;
    const etas = [...liveRows(base.eta_i_range), ...Object.keys(edits).map(Number)];
    return etas.every((eta) => this.rows.get(rowKey(eta)));
  }

  /**
   * Solve a live refit: `job` {base, fit (the fit on screen, the start),
   * edits ({eta key: rgb}), theta, eta (the plot's eta_i), editAt}.
   */
  request(job) {
    this.wanted = job;
    if (this.inFlight === null) this.#send();
  }

  /** Forget the move waiting and drop the answer under way (the drag ended, a base opened). */
  drop() {
    this.wanted = null;
    this.seq += 1;
  }

  #send() {
    const job = this.wanted;
    this.wanted = null;
    if (!job) return;
    const [lo, hi] = job.base.eta_i_range;
    const kind = modelKind(job.base), solver = kind.liveSolver;
    const degree = SOLVERS[solver].degree([lo, hi]);
    const baseRows = {};
    for (const [name, rows] of this.rows) if (rows) baseRows[name] = rows;
    job.seq = ++this.seq;
    job.degree = degree;
    job.kind = kind;
    job.sentAt = now();
    this.inFlight = job;
    this.worker.postMessage({
      id: job.seq, solver, baseRows, range: [lo, hi], degree, blendWidth: BLEND_WIDTH,
      start: flatCoefficients(job.fit.coefficients, degree + 1, kind),
      edits: Object.keys(job.edits).sort().map((eta) => ({ eta_i: Number(eta), angle_deg: job.theta, rgb: job.edits[eta] })),
    });
  }

  #answered(data) {
    const job = this.inFlight;
    this.inFlight = null;
    if (job && data.id === job.seq && data.id === this.seq && !data.error) {
      const d1 = job.degree + 1;
      const fit = {
        ...job.fit, id: `in-page-${job.seq}`, coefficients: nestedCoefficients(data.coefficients16, d1, job.kind),
        degree: job.degree,
        // The worker's clock is its own: its start and end (epoch ms) on this page's clock.
        inPage: { bestEffort: data.bestEffort, ms: data.ms, startedAt: data.startedAt - origin(), endedAt: data.endedAt - origin() },
      };
      const mu = job.theta.map((t) => (t === 90 ? 0 : Math.cos((t * Math.PI) / 180)));
      const values = SOLVERS[job.kind.liveSolver].values;
      const model = values(data.coefficients16, mu, mu.map(() => job.eta), job.base.eta_i_range, d1);
      this.io.show({ fit, model, job });
    } else if (data.error && this.io.onError) {
      this.io.onError(data.error);
    }
    if (this.wanted) this.#send();
  }
}
