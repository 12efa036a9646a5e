// Compare mode's Delta E 2000 (static/editor/compare.js) against published
// values: Sharma, Wu and Dalal (2005), Table 1 (CIEDE2000 test data), and
// ACEScg white and black in L*a*b*. tests/static/test_editor_compare_de.py
// checks it against fitting.colour.delta_e.delta_E_map on random colours.

import assert from "node:assert/strict";
import { test } from "node:test";

import { ACEScg_to_Lab, curvesDeltaE, delta_E_2000 } from "../../../static/editor/compare.js";

// Pairs 1, 7, 13, 17, 19, 25, 31, 34 of Sharma et al. (2005), Table 1, with their Delta E 00.
const SHARMA = [
  [[50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425],
  [[50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669],
  [[50.0, 2.49, -0.001], [50.0, -2.49, 0.0011], 7.2195],
  [[50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492],
  [[50.0, 2.5, 0.0], [50.0, 3.1736, 0.5854], 1.0],
  [[60.2574, -34.0099, 36.2677], [60.4626, -34.1751, 39.4387], 1.2644],
  [[90.8027, -2.0831, 1.441], [91.1528, -1.6435, 0.0447], 1.4441],
  [[2.0776, 0.0795, -1.135], [0.9033, -0.0636, -0.5514], 0.9082],
];

test("CIEDE2000 meets Sharma et al.'s test data to 1e-4", () => {
  for (const [a, b, expected] of SHARMA) {
    assert.ok(Math.abs(delta_E_2000(a, b) - expected) < 1e-4, `${a} ${b}: ${delta_E_2000(a, b)} vs ${expected}`);
    assert.ok(Math.abs(delta_E_2000(b, a) - expected) < 1e-4, "symmetric");
  }
  assert.equal(delta_E_2000([40, 10, -5], [40, 10, -5]), 0);
});

test("ACEScg white is L 100, a = b = 0; black is 0", () => {
  const white = ACEScg_to_Lab([1, 1, 1]);
  assert.ok(Math.abs(white[0] - 100) < 1e-9 && Math.abs(white[1]) < 1e-9 && Math.abs(white[2]) < 1e-9, `${white}`);
  assert.deepEqual(ACEScg_to_Lab([0, 0, 0]).map((v) => Math.round(v * 1e9) / 1e9), [0, 0, 0]);
});

test("curvesDeltaE: mean, max and the angle of the max; refuses curves of other lengths", () => {
  const theta = [0, 45, 90];
  const a = [[0.5, 0.4, 0.3], [0.6, 0.5, 0.4], [1, 1, 1]];
  const b = [[0.5, 0.4, 0.3], [0.7, 0.5, 0.4], [1, 1, 1]];
  const d = curvesDeltaE(a, b, theta);
  assert.equal(d.atDeg, 45);
  assert.ok(d.max > 1 && Math.abs(d.mean - d.max / 3) < 1e-12, JSON.stringify(d));
  assert.throws(() => curvesDeltaE(a, b.slice(1), theta), /2 samples for 3 angles|3 and 2 samples/);
});
