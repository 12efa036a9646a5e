// The page's live step of the exact-Fresnel conductor kind
// (static/editor/live_rgb_conductor.js) against the server's: the same
// target and samples, exported from Python by tests/static/live_rgb_cases.py
// (the live problem of fit_curves with LIVE_SETTINGS for that kind), for a
// few edits of several materials (node --test; run from pytest by
// tests/static/test_editor_js.py).
//
// Tolerances (docs/editor.md, "Live editing"): the exact Fresnel and its n,
// k derivatives within 1e-12; the target built in the page within 1e-12; the
// solve's n, k within 1e-4 relative (both converge to the same optimum by
// other steps; a large k is the flattest direction), the float16 n, k within
// two float16 steps of the server's and the model within 1e-6 in reflectance
// on the live samples.

import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { existsSync } from "node:fs";
import { dirname, join } from "node:path";
import { test } from "node:test";
import { fileURLToPath } from "node:url";

import { liveTarget } from "../../../static/editor/live_solve.js";
import {
  fresnelConductor, liveStepRGBConductor, rgbConductorValues,
} from "../../../static/editor/live_rgb_conductor.js";

const ROOT = join(dirname(fileURLToPath(import.meta.url)), "..", "..", "..");
const PYTHON = existsSync(join(ROOT, ".venv", "bin", "python")) ? join(ROOT, ".venv", "bin", "python") : "python3";
const { cases: CASES, fresnel: FRESNEL } = JSON.parse(
  execFileSync(PYTHON, ["-m", "tests.static.live_rgb_cases"], { cwd: ROOT, maxBuffer: 1 << 26 }));

const maxDiff = (a, b) => Math.max(...a.map((v, i) => Math.abs(v - b[i])));
const halfStep = (v) => 2 ** (Math.max(Math.floor(Math.log2(Math.abs(v) || 2 ** -14)), -14) - 10);

test("the export holds edits of several materials", () => {
  assert.ok(CASES.length >= 4);
  assert.ok(new Set(CASES.map((c) => c.name.split(" ")[0])).size >= 4);
});

test("the exact conductor Fresnel and its derivatives are the server's", () => {
  for (const { at, R, dn, dk } of FRESNEL) {
    const got = fresnelConductor(...at);
    assert.ok(Math.abs(got.R - R) < 1e-12, `R at ${at}: ${got.R} vs ${R}`);
    assert.ok(Math.abs(got.dn - dn) < 1e-12, `dR/dn at ${at}: ${got.dn} vs ${dn}`);
    assert.ok(Math.abs(got.dk - dk) < 1e-12, `dR/dk at ${at}: ${got.dk} vs ${dk}`);
  }
});

for (const c of CASES) {
  test(`live step agrees with the server: ${c.name}`, () => {
    // The page's target from the base's rows, as the worker builds it.
    const built = liveTarget([c.edit], (e) => c.base_rows[e.toFixed(6)], c.range, 0.5);
    assert.equal(built.mu.length, c.mu.length);
    assert.ok(maxDiff(built.target.flat(), c.target.flat()) < 1e-12);
    assert.ok(maxDiff(built.eta, c.eta) < 1e-12);
    assert.ok(c.weights.every((w) => w === 1), "unit weights: the worker's (null) are the same");
    const step = liveStepRGBConductor({ target: built.target, mu: built.mu, eta: built.eta, weights: null });
    step.coefficients.forEach((v, i) => {
      assert.ok(Math.abs(v - c.x[i]) < 1e-4 * Math.max(1, Math.abs(c.x[i])), `n, k ${step.coefficients} vs ${c.x}`);
    });
    step.coefficients16.forEach((v, i) => {
      const server = c.live.coefficients16[i];
      assert.ok(Math.abs(v - server) <= 2 * halfStep(server) * 1.0001, `float16 ${i}: ${v} vs ${server}`);
    });
    assert.equal(step.bestEffort, c.live.best_effort);
    const ours = rgbConductorValues(step.coefficients, c.mu, c.eta).flat();
    const theirs = rgbConductorValues(c.x, c.mu, c.eta).flat();
    assert.ok(maxDiff(ours, theirs) < 1e-6);
  });
}
