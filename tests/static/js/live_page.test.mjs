// The editor's live refits in the page (static/editor/live_page.js) against a
// fake worker and fake rows: the base's rows asked once, one solve in flight,
// the latest move solved next, answers dropped after the drag (node --test;
// run from pytest by tests/static/test_editor_js.py).

import assert from "node:assert/strict";
import { test } from "node:test";

import { LiveRefit, flatCoefficients, liveRows, nestedCoefficients } from "../../../static/editor/live_page.js";
import { DOMAIN } from "./domain.mjs"; // the server's kinds, each naming its live solver

const C = { F0: [[0.9, -0.1, 0.05], [0.7, -0.2, 0.1], [0.4, -0.3, 0.2]], a: [[1, 0, 0], [1, 0, 0], [1, 0, 0]],
            alpha: [[2, 0, 0], [2, 0, 0], [2, 0, 0]] };
const BASE = { id: "base", model: DOMAIN.default_model, eta_i_range: [1, 2.5], coefficients: C };
const THETA = Array.from({ length: 46 }, (_, i) => 2 * i);

function harness() {
  const posted = [], shown = [], asked = [];
  const worker = { postMessage: (m) => posted.push(m), onmessage: null };
  let resolveRows = [];
  const live = new LiveRefit({
    worker,
    rowsOf: (base, eta) => {
      asked.push(eta);
      return new Promise((resolve) => resolveRows.push(() => resolve(Array.from({ length: 12 }, () => [0.5, 0.5, 0.5]))));
    },
    show: (answer) => shown.push(answer),
  });
  const answer = (id) => worker.onmessage({ data: { id, coefficients16: flatCoefficients(C, 3), bestEffort: false, ms: 1 } });
  const rowsIn = async () => { resolveRows.splice(0).forEach((r) => r()); await new Promise((r) => setTimeout(r, 0)); };
  return { live, posted, shown, asked, answer, rowsIn, worker };
}

const job = (value) => ({ base: BASE, fit: BASE, edits: { "1.50": THETA.map(() => [value, 0.5, 0.5]) }, theta: THETA,
                          eta: 1.5, editAt: 0 });

test("the base's rows are asked once per eta_i; solves wait for them", async () => {
  const h = harness();
  h.live.prepare(BASE, [1.5, 1.6]);
  h.live.prepare(BASE, [1.6]);
  assert.deepEqual(h.asked, [...liveRows([1, 2.5]), 1.6], "the live rows (1.5 among them) and 1.6, once each");
  assert.equal(h.live.ready(BASE, { "1.60": [] }), false);
  await h.rowsIn();
  assert.equal(h.live.ready(BASE, { "1.60": [] }), true);
  assert.equal(h.live.ready(BASE, { "1.70": [] }), false, "an eta_i whose row is not in");
});

test("one solve in flight; the latest move is solved next; its answer is drawn as a fit", async () => {
  const h = harness();
  h.live.prepare(BASE, [1.5]);
  await h.rowsIn();
  h.live.request(job(0.1));
  h.live.request(job(0.2));
  h.live.request(job(0.3));
  assert.equal(h.posted.length, 1);
  h.answer(h.posted[0].id);
  assert.equal(h.posted.length, 2, "the latest waiting move, not the one between");
  assert.equal(h.posted[1].edits[0].rgb[0][0], 0.3);
  assert.equal(h.posted[1].edits[0].eta_i, 1.5);
  assert.deepEqual(h.posted[1].start, flatCoefficients(C, 3));
  assert.equal(h.shown.length, 1);
  const { fit, model } = h.shown[0];
  assert.deepEqual(fit.coefficients, C);
  assert.match(fit.id, /^in-page-/);
  assert.equal(model.length, THETA.length);
  assert.ok(Math.abs(model[0][0] - 0.9 - (-0.1 / 3) - 0.05 / 9) < 1e-12, "F0 at normal incidence, t = 1/3");
});

test("an answer after the drag ended is dropped", async () => {
  const h = harness();
  h.live.prepare(BASE, [1.5]);
  await h.rowsIn();
  h.live.request(job(0.1));
  h.live.drop();
  h.answer(h.posted[0].id);
  assert.equal(h.shown.length, 0);
});

test("the exact-Fresnel kind is solved in the page: n, k per channel, its exact Fresnel drawn", async () => {
  const kind = DOMAIN.model_kinds.find((k) => k.live_solver === "exact-fresnel");
  assert.ok(kind, "the server names a kind solved by the exact-Fresnel live step");
  const N = { n: [0.2, 0.4, 1.4], k: [3.5, 2.5, 1.9] };
  const rgb = { id: "rgb", model: kind.name, eta_i_range: [1, 2.5], coefficients: N };
  const h = harness();
  assert.equal(h.live.supports(rgb), true);
  h.live.prepare(rgb, [1.5]);
  await h.rowsIn();
  h.live.request({ ...job(0.2), base: rgb, fit: rgb });
  assert.equal(h.posted.length, 1);
  assert.equal(h.posted[0].solver, "exact-fresnel");
  assert.equal(h.posted[0].degree, 0);
  assert.deepEqual(h.posted[0].start, [0.2, 0.4, 1.4, 3.5, 2.5, 1.9]);
  h.worker.onmessage({ data: { id: h.posted[0].id, coefficients16: [0.2, 0.4, 1.4, 3.5, 2.5, 1.9], bestEffort: false, ms: 1 } });
  const { fit, model } = h.shown[0];
  assert.deepEqual(fit.coefficients, N);
  // At normal incidence under eta_i 1.5: ((n - 1.5)^2 + k^2) / ((n + 1.5)^2 + k^2).
  const F0 = ((0.2 - 1.5) ** 2 + 3.5 ** 2) / ((0.2 + 1.5) ** 2 + 3.5 ** 2);
  assert.ok(Math.abs(model[0][0] - F0) < 1e-12);
});

test("a kind the page has no solver of is left to the server", () => {
  const h = harness();
  const other = { id: "x", model: "a kind the server did not list", eta_i_range: [1, 2.5], coefficients: {} };
  assert.equal(h.live.supports(other), false);
  h.live.prepare(other, [1.5]);
  assert.deepEqual(h.asked, []);
  assert.equal(h.live.ready(other, {}), false);
});

test("coefficients round-trip between the API's form and the solver's", () => {
  assert.deepEqual(nestedCoefficients(flatCoefficients(C, 3), 3), C);
  assert.deepEqual(flatCoefficients({ F0: [[1], [2], [3]], a: [[4], [5], [6]], alpha: [[7], [8], [9]] }, 3).slice(0, 6),
                   [1, 0, 0, 2, 0, 0]);
  const nk = { parameters: ["n", "k"], maxDegree: 0 }, N = { n: [0.2, 0.4, 1.4], k: [3.5, 2.5, 1.9] };
  assert.deepEqual(nestedCoefficients(flatCoefficients(N, 1, nk), 1, nk), N);
});
