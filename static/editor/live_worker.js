// The module worker of the editor's live refits: builds the live target
// from the edits and the base's rows, solves the live step by the kind's
// solver (`solver`, live_page.js SOLVERS: live_solve.js for the polynomial
// with the [0, 1] rule, live_rgb_conductor.js for per-channel n, k) and answers {id, coefficients16, bestEffort, ms, startedAt,
// endedAt (epoch ms: the page puts them on its own clock)}, or
// {id, error}. One message at a time; the page sends the next when this
// one answers (live_page.js), so a drag never queues stale work here.

import { liveStepRGBConductor } from "./live_rgb_conductor.js";
import { liveStep, liveTarget } from "./live_solve.js";

// By the name the server gives a kind's live solver (kinds.js liveSolver).
const SOLVE = {
  polynomial: liveStep,
  "exact-fresnel": ({ target, mu, eta, weights }) => liveStepRGBConductor({ target, mu, eta, weights }),
};

self.onmessage = ({ data }) => {
  const { id, solver, edits, baseRows, range, degree, start, blendWidth } = data;
  const startedAt = performance.timeOrigin + performance.now();
  try {
    const baseAt = (eta) => {
      const rows = baseRows[eta.toFixed(6)];
      if (!rows) throw new Error(`no base row at eta_i ${eta}`);
      return rows;
    };
    const { target, mu, eta } = liveTarget(edits, baseAt, range, blendWidth);
    if (!Object.hasOwn(SOLVE, solver)) throw new Error(`no live solver ${solver}`);
    const result = SOLVE[solver]({ target, mu, eta, range, degree, weights: null, start });
    self.postMessage({ id, coefficients16: result.coefficients16, bestEffort: result.bestEffort, ms: result.ms,
                       startedAt, endedAt: performance.timeOrigin + performance.now() });
  } catch (error) {
    self.postMessage({ id, error: error.message });
  }
};

// Warm the solver once at start (a grey target): the first drag's steps then run compiled code.
(() => {
  const range = [1, 2.5];
  const edit = { eta_i: 1.5, angle_deg: [0, 90], rgb: [[0.5, 0.5, 0.5], [1, 1, 1]] };
  const rows = liveTarget([edit], () => Array.from({ length: 12 }, () => [0.5, 0.5, 0.5]), range, 0.5);
  const start = [0.5, 0, 0, 0.5, 0, 0, 0.5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0];
  for (let i = 0; i < 3; i++) liveStep({ ...rows, range, degree: 2, weights: null, start });
  liveStepRGBConductor({ ...rows, weights: null });
})();
