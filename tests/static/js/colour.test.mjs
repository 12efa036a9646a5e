// The colour controls' arithmetic (static/editor/colour.js) and the falloff of
// a dragged point (static/editor/falloff.js, through the state's drag action).
// The conversions against colour-science: tests/static/test_editor_colour.py.

import test from "node:test";
import assert from "node:assert/strict";

import {
  ACEScgToRec709, coloursOf, colourRows, hexToLinear, linearToHex, rec709ToACEScg, srgbDecode, srgbEncode, warmer,
} from "../../../static/editor/colour.js";
import { falloffWeight, FALLOFFS } from "../../../static/editor/falloff.js";
import { HANDLES, createStore, key } from "../../../static/editor/state.js";

const THETA = Array.from({ length: 46 }, (_, i) => 2 * i);
const near = (a, b, tol, what) => a.forEach((v, i) => assert.ok(Math.abs(v - b[i]) <= tol, `${what}: ${a} vs ${b}`));

test("hex round-trips through linear Rec.709; bad hex is refused by rule", () => {
  for (const hex of ["#000000", "#ffffff", "#d4af37", "#b87333", "#0a1b2c"]) {
    assert.equal(linearToHex(hexToLinear(hex)), hex);
  }
  assert.deepEqual(hexToLinear("FFFFFF"), [1, 1, 1]);
  assert.equal(linearToHex([2, -1, 0.5]), "#ff00bc", "clipped to [0, 1]");
  assert.throws(() => hexToLinear("#abc"), /#rrggbb/);
  assert.throws(() => hexToLinear("#gggggg"), /#rrggbb/);
  for (const v of [0, 0.002, 0.04045, 0.2, 0.9, 1]) assert.ok(Math.abs(srgbDecode(srgbEncode(v)) - v) < 1e-12);
});

test("Rec.709 and ACEScg: white stays white, the two matrices are inverses", () => {
  near(rec709ToACEScg([1, 1, 1]), [1, 1, 1], 1e-12, "white");
  near(ACEScgToRec709(rec709ToACEScg([0.9, 0.3, 0.05])), [0.9, 0.3, 0.05], 1e-12, "round trip");
});

test("warmth: 0 keeps the tint, warmer raises red over blue at the same luminance, clipped", () => {
  const tint = [0.6, 0.6, 0.6]; // no channel clipped at the knob's ends
  assert.deepEqual(warmer(tint, 0), tint);
  const warm = warmer(tint, 1), cool = warmer(tint, -1);
  assert.ok(warm[0] > warm[1] && warm[1] > warm[2] && cool[2] > cool[1] && cool[1] > cool[0]);
  const Y = (c) => 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
  assert.ok(Math.abs(Y(warm) - Y(tint)) < 1e-12 && Math.abs(Y(cool) - Y(tint)) < 1e-12);
  assert.ok(warmer([1, 1, 1], 1).every((v) => v >= 0 && v <= 1));
  assert.deepEqual(warmer(tint, 5), warm, "the knob stops at 1");
});

test("the colours read back from a curve: F0 at 0 degrees, the tint at cos theta 1/7", () => {
  // A grey Schlick curve with tint 1: F0 0.5 everywhere, the tint 1 at 82 degrees.
  const f0 = 0.5;
  const curve = THETA.map((t) => { const mu = Math.cos((t * Math.PI) / 180); const v = f0 + (1 - f0) * (1 - mu) ** 5; return [v, v, v]; });
  const got = coloursOf(curve, THETA);
  near(got.f0, [0.5, 0.5, 0.5], 1e-12, "F0");
  near(got.f82, [1, 1, 1], 0.02, "tint (linear in angle between 80 and 82 degrees)");
});

test("a colour edit sets the curves every 0.5 over the domain, at eta_i and where the colours are seen", () => {
  assert.deepEqual(colourRows([1, 2.5], 1.5, 1), [1, 1.5, 2, 2.5]);
  assert.deepEqual(colourRows([1, 2.5], 1.33, 1.33), [1, 1.33, 1.5, 2, 2.5]);
  assert.deepEqual(colourRows([1.2, 1.8], 1.3, 1), [1.2, 1.3, 1.7, 1.8], "in air outside the domain: not a row");
});

test("falloff none moves the point alone: every other handle keeps its value", () => {
  for (const handle of HANDLES) {
    for (const other of HANDLES) {
      if (other !== handle) assert.equal(falloffWeight(other, handle, "none", HANDLES), 0, `${other} for ${handle}`);
    }
    assert.equal(falloffWeight(handle, handle, "none", HANDLES), 1);
    assert.equal(falloffWeight(90, handle, "none", HANDLES), 0, "grazing stays");
  }
  assert.ok(falloffWeight(55, 60, "none", HANDLES) === 0.5, "between the point and its neighbour: partly");
  assert.ok(falloffWeight(70, 60, "narrow", HANDLES) > 0.3 && falloffWeight(70, 60, "wide", HANDLES) > falloffWeight(70, 60, "narrow", HANDLES));
  assert.equal(FALLOFFS.narrow, 9);
  assert.throws(() => falloffWeight(0, 60, "huge", HANDLES), /falloff must be one of none, narrow, wide/);
});

test("the state's drag follows the chosen falloff; a colour edit is one undo step", () => {
  const store = createStore();
  const s = store.state;
  store.dispatch("openBase", { id: "au", kind: "library", eta_i_range: [1, 2.5] });
  store.dispatch("curves", { base: { eta_i: 1.5, theta_deg: THETA, reference: THETA.map(() => [0.5, 0.5, 0.5]), model: null } });
  const at = (deg) => s.edits[key(1.5)][THETA.indexOf(deg)][0];
  store.dispatch("drag", { channel: 0, handle: 4, value: 0.8 }); // 60 degrees
  assert.equal(at(60), 0.8);
  assert.equal(at(50), 0.5, "none: the neighbour at 50 stays");
  assert.equal(at(70), 0.5, "none: the neighbour at 70 stays");
  store.dispatch("dragEnd");
  store.dispatch("falloff", "wide");
  store.dispatch("drag", { channel: 0, handle: 2, value: 0.2 }); // 36 degrees
  store.dispatch("dragEnd");
  assert.ok(at(50) < 0.5, "wide: the neighbour moves too");
  assert.throws(() => store.dispatch("falloff", "huge"), /falloff/);
  const edits = { [key(1)]: THETA.map(() => [0.9, 0.7, 0.3]), [key(2)]: THETA.map(() => [0.8, 0.6, 0.2]) };
  const before = JSON.stringify(s.edits);
  store.dispatch("colour", edits);
  assert.deepEqual(Object.keys(s.edits).sort(), ["1.00", "2.00"]);
  store.dispatch("undo");
  assert.equal(JSON.stringify(s.edits), before);
});
