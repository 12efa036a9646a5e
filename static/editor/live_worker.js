// The module worker of the editor's live refits: builds the live target
// from the edits and the base's rows, solves the live step
// (live_solve.js) and answers {id, coefficients16, bestEffort, ms, startedAt,
// endedAt (epoch ms: the page puts them on its own clock)}, or
// {id, error}. One message at a time; the page sends the next when this
// one answers (live_page.js), so a drag never queues stale work here.

import { liveStep, liveTarget } from "./live_solve.js";

self.onmessage = ({ data }) => {
  const { id, edits, baseRows, range, degree, start, blendWidth } = data;
  const startedAt = performance.timeOrigin + performance.now();
  try {
    const baseAt = (eta) => {
      const rows = baseRows[eta.toFixed(6)];
      if (!rows) throw new Error(`no base row at eta_i ${eta}`);
      return rows;
    };
    const { target, mu, eta } = liveTarget(edits, baseAt, range, blendWidth);
    const result = liveStep({ target, mu, eta, range, degree, weights: null, start });
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
})();
