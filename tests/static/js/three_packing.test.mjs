// The three.js package's own float16 packing (web/three/src/packing.js,
// which imports nothing outside the package) against the editor's
// (static/kinds.js): the same halves and words for every value: node
// --test, run from pytest by tests/static/test_editor_js.py.

import assert from "node:assert/strict";
import { test } from "node:test";

import { DOMAIN } from "./domain.mjs";
import * as editor from "../../../static/kinds.js";
import * as pkg from "../../../web/three/src/packing.js";

test("the package's halves are the editor's", () => {
  const values = [0, -0, 1, -1, 65504, 65520, 1e6, -1e6, 6.1e-5, 5.96e-8, 2.98e-8, 1e-9, Infinity, -Infinity, NaN];
  let x = 0.123456789;
  for (let i = 0; i < 2000; i++) {
    x = (x * 9301 + 0.49297) % 1; // deterministic spread over many exponents
    values.push((x - 0.5) * 10 ** ((i % 14) - 7));
  }
  for (const v of values) assert.equal(pkg.halfBits(v), editor.halfBits(v), String(v));
});

test("the package's words are the editor's", () => {
  const coefficients = {
    F0: [[0.95, 0.01, -0.002], [0.64, 0.02], [0.54]],
    a: [[0.1, 0.2, 0.3], [0.05, 0.01, 0], [0.2, -0.1, 0.01]],
    alpha: [[5.5, -0.25, 0.125], [4, 0.5, 0], [3.25, 0, 0]],
  };
  const kind = editor.modelKindNamed(DOMAIN.default_model);
  assert.deepEqual(kind.parameters, ["F0", "a", "alpha"]);
  assert.deepEqual(Array.from(pkg.packedWords(coefficients)), Array.from(kind.words(coefficients)));
  const halves = [1, 2, 3, 4, 5].map(editor.halfBits);
  assert.deepEqual(Array.from(pkg.wordsOf(halves)), Array.from(editor.wordsOf(halves)));
});
