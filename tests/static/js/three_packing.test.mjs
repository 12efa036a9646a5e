// The three.js package's own float16 packing (web/three/src/packing.js,
// which imports nothing outside the package) against the editor's
// (static/kinds.js): the same halves and words for every value and every
// kind the server lists, and the package's generated kinds (web/three/src/
// generated/kinds.js) the server's: node --test, run from pytest by
// tests/static/test_editor_js.py.

import assert from "node:assert/strict";
import { test } from "node:test";

import { DOMAIN } from "./domain.mjs";
import * as editor from "../../../static/kinds.js";
import * as pkg from "../../../web/three/src/packing.js";
import { MODEL_KINDS } from "../../../web/three/src/kinds.js";

test("the package's halves are the editor's", () => {
  const values = [0, -0, 1, -1, 65504, 65520, 1e6, -1e6, 6.1e-5, 5.96e-8, 2.98e-8, 1e-9, Infinity, -Infinity, NaN];
  let x = 0.123456789;
  for (let i = 0; i < 2000; i++) {
    x = (x * 9301 + 0.49297) % 1; // deterministic spread over many exponents
    values.push((x - 0.5) * 10 ** ((i % 14) - 7));
  }
  for (const v of values) assert.equal(pkg.halfBits(v), editor.halfBits(v), String(v));
});

test("the package's kinds are the server's", () => {
  assert.deepEqual(
    MODEL_KINDS.map((k) => [k.name, k.description, k.parameters, k.maxDegree, k.splitSum]),
    DOMAIN.model_kinds.map((k) => [k.name, k.description, k.parameters, k.max_degree, k.split_sum]),
  );
});

test("the package's words are the editor's, for every kind", () => {
  let x = 0.37;
  const next = () => { x = (x * 9301 + 0.49297) % 1; return 8 * (x - 0.25); };
  for (const kind of MODEL_KINDS) {
    const editorKind = editor.modelKindNamed(kind.name);
    // Each degree from 0 up, a row shorter than maxDegree + 1 padded with 0.
    for (let degree = 0; degree <= kind.maxDegree; degree++) {
      const coefficients = Object.fromEntries(kind.parameters.map((p) => [p, [0, 1, 2].map(() => (
        kind.maxDegree === 0 ? next() : Array.from({ length: degree + 1 }, next)))]));
      const words = Array.from(pkg.wordsFor(kind, coefficients));
      assert.deepEqual(words, Array.from(editorKind.words(coefficients)), kind.name);
      assert.ok(words.some((w) => w !== 0), kind.name);
    }
  }
  const halves = [1, 2, 3, 4, 5].map(editor.halfBits);
  assert.deepEqual(Array.from(pkg.wordsOf(halves)), Array.from(editor.wordsOf(halves)));
});
