// The editor's state and its named actions (static/editor/state.js),
// the figures it reads from a fit (figures.js) and the model kinds the
// browser draws (static/kinds.js): node --test, run from pytest by
// tests/static/test_editor_js.py.

import assert from "node:assert/strict";
import { test } from "node:test";

import { readFigures, REACH_DE } from "../../../static/editor/figures.js";
import {
  HANDLES, SAMPLES, bump, createStore, editsOf, fitted, key, liveStart, snapshot, target, unsaved,
} from "../../../static/editor/state.js";
import { DOMAIN } from "./domain.mjs";
import { halfBits, modelKind, modelKindNamed, modelKindNames } from "../../../static/kinds.js";

const THETA = Array.from({ length: SAMPLES }, (_, i) => 2 * i);
const flat = (v) => THETA.map(() => [v, v, v]);
const BASE = { id: "au", kind: "library", model: "coated-conductor", eta_i_range: [1, 2.5] };

function opened() {
  const store = createStore();
  store.dispatch("openBase", BASE);
  store.dispatch("curves", { base: { eta_i: 1.5, theta_deg: THETA, reference: flat(0.5), model: flat(0.45) } });
  store.dispatch("shown", { fit: BASE });
  return store;
}

test("a drag edits the target at the current eta_i with a smooth bump; 90 degrees stays", () => {
  const store = opened();
  const s = store.state;
  assert.deepEqual(target(s), flat(0.5), "a library base starts from its measured reference");
  assert.equal(store.dispatch("drag", { channel: 1, handle: 3, value: 0.7, pointer: true }), true);
  const edit = s.edits[key(1.5)];
  const at = (deg) => edit[THETA.indexOf(deg)];
  assert.equal(at(50)[1], 0.7);
  assert.ok(at(44)[1] > 0.5 && at(44)[1] < 0.7, "neighbours move by less");
  assert.equal(at(50)[0], 0.5, "other channels stay");
  assert.equal(at(90)[1], 0.5, "grazing stays");
  assert.equal(liveStart(s), "au", "live while a pointer drags");
  assert.equal(store.dispatch("drag", { channel: 1, handle: 3, value: 0.7, pointer: true }), false, "no move, no edit");
  store.dispatch("dragEnd");
  assert.equal(liveStart(s), null);
  assert.equal(s.undo.length, 1, "one undo step per drag");
});

test("'All three' scales the channels: the hue stays at the point", () => {
  const rows = bump(THETA.map(() => [0.8, 0.4, 0.2]), THETA, 50, 0, 0.4, true);
  const i = THETA.indexOf(50);
  assert.deepEqual(rows[i].map((v) => +v.toFixed(12)), [0.4, 0.2, 0.1]);
  assert.throws(() => bump(flat(0.5), THETA, 51, 0, 0.1), /51/);
});

test("a drag waits for the curves of the slider's eta_i", () => {
  const store = opened();
  store.dispatch("setEta", 2.0);
  assert.equal(store.dispatch("drag", { channel: 0, handle: 2, value: 0.1 }), false);
});

test("undo, redo and reset move between snapshots; a new edit clears redo", () => {
  const store = opened();
  const s = store.state;
  store.dispatch("drag", { channel: 0, handle: 2, value: 0.3 });
  store.dispatch("dragEnd");
  const one = snapshot(s);
  store.dispatch("drag", { channel: 0, handle: 4, value: 0.2 });
  store.dispatch("dragEnd");
  const two = snapshot(s);
  assert.equal(store.dispatch("undo"), true);
  assert.equal(snapshot(s), one);
  assert.equal(store.dispatch("undo"), true);
  assert.equal(snapshot(s), "{}");
  assert.equal(store.dispatch("undo"), false, "nothing left to undo");
  store.dispatch("redo");
  store.dispatch("redo");
  assert.equal(snapshot(s), two);
  store.dispatch("reset");
  assert.equal(snapshot(s), "{}");
  store.dispatch("undo");
  assert.equal(snapshot(s), two, "reset is undoable");
  store.dispatch("undo");
  store.dispatch("drag", { channel: 2, handle: 1, value: 0.9 });
  store.dispatch("dragEnd");
  assert.equal(s.redo.length, 0);
});

test("gentler moves every edit halfway back to where it started (undoable)", () => {
  const store = opened();
  const s = store.state;
  store.dispatch("drag", { channel: 0, handle: 3, value: 0.9 });
  store.dispatch("dragEnd");
  store.dispatch("gentler", { [key(1.5)]: flat(0.5) });
  assert.ok(Math.abs(s.edits[key(1.5)][THETA.indexOf(50)][0] - 0.7) < 1e-12);
  store.dispatch("undo");
  assert.equal(s.edits[key(1.5)][THETA.indexOf(50)][0], 0.9);
});

test("unsaved and fitted follow the fit shown and the save", () => {
  const store = opened();
  const s = store.state;
  assert.equal(unsaved(s), false);
  store.dispatch("drag", { channel: 0, handle: 3, value: 0.9 });
  assert.equal(fitted(s), false, "the edit is not fitted yet");
  store.dispatch("shown", { fit: { id: "draft" }, edits: snapshot(s) });
  assert.equal(fitted(s), true);
  assert.equal(unsaved(s), true);
  store.dispatch("saved", "draft");
  assert.equal(unsaved(s), false);
  store.dispatch("openBase", { ...BASE, eta_i_range: [1, 1.2] });
  assert.equal(s.eta, 1.2, "eta_i kept in the new base's domain");
  assert.deepEqual([s.edits, s.undo, s.redo], [{}, [], []]);
});

test("subscribers see every action; unknown actions are refused by name", () => {
  const store = opened();
  const seen = [];
  store.subscribe((name) => seen.push(name));
  store.dispatch("setEta", 1.7);
  store.dispatch("undo");
  assert.deepEqual(seen, ["setEta", "undo"]);
  assert.throws(() => store.dispatch("nope"), /"nope"/);
  assert.equal(HANDLES.every((h) => THETA.includes(h)), true);
});

test("figures: the fit's one figure (metrics.figure), its target in words, the reach", () => {
  const against = "your edited curves (the whole edited target, 46 angles x 31 eta_i)";
  const edit = { kind: "curves", metrics: { model: { delta_E_mean: 0.2 }, figure: {
    against, delta_E_mean: 0.339, delta_E_max: REACH_DE + 1, max_at: { eta_i: 1.5, theta_deg: 58 } } } };
  const f = readFigures(edit);
  assert.equal(f.mean, 0.339);
  assert.equal(f.label, `Against ${against}, mean ΔE`);
  assert.deepEqual(f.reach, { max: REACH_DE + 1, thetaDeg: 58, etaI: 1.5 });
  const library = readFigures({ kind: "library", metrics: { figure: {
    against: "the measured metal (1 nm spectral reference), 30 x 30 grid", delta_E_mean: 0.14,
    delta_E_max: REACH_DE + 1, max_at: { eta_i: 1, theta_deg: 85 } } } });
  assert.equal(library.mean, 0.14);
  assert.equal(library.reach, null, "only an edit can be beyond the model's reach");
  assert.match(library.label, /measured metal/);
  assert.equal(readFigures({ kind: "library", metrics: {} }).mean, null);
  assert.deepEqual(f.unfollowed, [], "no warning when the server gives none");
});

test("figures: the server's warnings for edited curves the fit cannot follow", () => {
  const said = "edit not followed: the fit stays 2.10 mean Delta E 2000 from the edited curve at eta_i 1.5 " +
    "(max 6.00 at 60 degrees); the model cannot bend that way";
  const edit = { kind: "curves", metrics: { figure: { delta_E_mean: 0.5, delta_E_max: 1.0, max_at: null },
    details: { warnings: [said, 7] } } };
  const f = readFigures(edit);
  assert.deepEqual(f.unfollowed, [said], "every warning in words, nothing else");
  assert.equal(f.reach, null, "a warning shows without a miss past REACH_DE");
  const library = readFigures({ kind: "library", metrics: { figure: {}, details: { warnings: [said] } } });
  assert.deepEqual(library.unfollowed, [], "a measured metal's data warnings are not edits");
});

test("kinds: the server's registry, the words a renderer uploads, per kind; unknown kinds refused by name", () => {
  assert.deepEqual([1, 0.5, -2, 65504, 1e-8].map(halfBits), [0x3c00, 0x3800, 0xc000, 0x7bff, 0]);
  assert.deepEqual(modelKindNames(), DOMAIN.model_kinds.map((k) => k.name));
  const coated = modelKindNamed("coated-conductor");
  assert.equal(coated.splitSum, true);
  assert.match(coated.sources["cf_preview_model.glsl"], /vec3 cf_preview_model\(float NdotV/);
  const C = { F0: [[1, 0.5], [0, 0], [0, 0]], a: [[0], [0], [0]], alpha: [[0], [0], [0]] };
  const words = coated.words(C);
  assert.equal(words.length, 14);
  assert.equal(words[0], (0x3c00 | (0x3800 << 16)) >>> 0, "F0 R's first two powers in word 0");
  const rgb = modelKindNamed("rgb-conductor").words({ n: [1, 0.5, 2], k: [-2, 0, 1] });
  assert.deepEqual(Array.from(rgb.slice(0, 4)), [
    (0x3c00 | (0x3800 << 16)) >>> 0, (0x4000 | (0xc000 << 16)) >>> 0, (0 | (0x3c00 << 16)) >>> 0, 0,
  ]);
  const fit = { model: "rgb-conductor", eta_i_range: [1, 2.5], coefficients: { n: [0.2, 0.5, 1.3], k: [3, 2.3, 1.9] } };
  const kind = modelKind(fit);
  assert.equal(kind.splitSum, false);
  assert.match(kind.describe(fit), /^rgb-conductor/);
  assert.equal(modelKind({ coefficients: C, degree: 1, eta_i_range: [1, 2] }).name, DOMAIN.default_model);
  assert.throws(() => modelKind({ model: "schlick", coefficients: {} }), /`model`.*"schlick"/);
  assert.throws(() => modelKind({ model: "rgb-conductor", coefficients: { n: [1, 1], k: [0, 0, 0] } }), /coefficients\.n/);
});

test("a burst of key presses (drags with no dragEnd yet) is one undo step, even when undo comes first", () => {
  const store = opened();
  const s = store.state;
  for (const value of [0.52, 0.54, 0.56]) store.dispatch("drag", { channel: 0, handle: 3, value });
  assert.equal(s.undo.length, 0, "the burst is under way");
  assert.equal(store.dispatch("undo"), true, "undo ends the burst, then takes it back whole");
  assert.deepEqual(s.edits, {});
  assert.equal(s.undo.length, 0);
  assert.equal(s.redo.length, 1);
  assert.equal(s.dragStart, null);
});

test("editsOf: a stored request's curves at the editor's angles, by eta_i key", () => {
  const curve = { eta_i: 1.333, angle_deg: [0, 45, 90], rgb: [[0.2, 0.4, 0.6], [0.4, 0.6, 0.8], [1, 1, 1]] };
  const edits = editsOf([curve], THETA);
  assert.deepEqual(Object.keys(edits), ["1.33"]);
  const at = (deg) => edits["1.33"][THETA.indexOf(deg)];
  assert.deepEqual(at(0), [0.2, 0.4, 0.6]);
  assert.deepEqual(at(90), [1, 1, 1]);
  at(22).forEach((v, c) => assert.ok(Math.abs(v - (curve.rgb[0][c] + (22 / 45) * 0.2)) < 1e-12));
  // The editor's own angles come back exactly; cos theta is read as an angle.
  const same = editsOf([{ eta_i: 1.5, angle_deg: THETA, rgb: flat(0.3) }], THETA);
  assert.deepEqual(same["1.50"], flat(0.3));
  const byCos = editsOf([{ eta_i: 2, cos_theta: [1, 0], rgb: [[0, 0, 0], [1, 1, 1]] }], THETA);
  assert.ok(Math.abs(byCos["2.00"][THETA.indexOf(60)][1] - 60 / 90) < 1e-12);
});

test("reopened: the stored edits with no history, the fit saved; compare curves of another fit are dropped", () => {
  const store = opened();
  const s = store.state;
  store.dispatch("drag", { channel: 1, handle: 2, value: 0.7 });
  store.dispatch("dragEnd");
  store.dispatch("reopened", { edits: { "1.50": flat(0.6) }, fitId: "saved-fit" });
  assert.deepEqual([s.undo, s.redo, s.savedId], [[], [], "saved-fit"]);
  store.dispatch("shown", { fit: { id: "saved-fit" }, edits: snapshot(s) });
  assert.equal(unsaved(s), false);
  store.dispatch("compareWith", { fit: { id: "cu" }, label: "Cu" });
  assert.equal(store.dispatch("compareCurves", { fitId: "ag", eta: 1.5, model: flat(0.9) }), false);
  assert.equal(s.compare.model, null);
  assert.equal(store.dispatch("compareCurves", { fitId: "cu", eta: 1.5, model: flat(0.5) }), true);
  assert.equal(s.compare.eta, "1.50");
  store.dispatch("compareOff");
  assert.equal(s.compare, null);
});

test("a live fit from the page is drawn while a point is held, never the fit on screen", () => {
  const store = opened();
  const s = store.state;
  assert.equal(s.onScreen, "server");
  assert.equal(store.dispatch("liveShown", { model: flat(0.6) }), false, "no drag under way: dropped");
  store.dispatch("drag", { channel: 1, handle: 3, value: 0.7, pointer: true });
  assert.equal(store.dispatch("liveShown", { model: flat(0.6) }), true);
  assert.deepEqual(s.model, flat(0.6));
  assert.equal(s.onScreen, "page");
  assert.equal(s.fit, BASE, "ids, figures and downloads stay the server fit's");
  store.dispatch("dragEnd");
  assert.equal(store.dispatch("liveShown", { model: flat(0.7) }), false, "an answer after the release is dropped");
  store.dispatch("shown", { fit: { ...BASE, id: "full" }, model: flat(0.65) });
  assert.equal(s.onScreen, "server");
});

test("librarySearch: the ids found and, for a search that found none, the ids suggested; cleared with the search", () => {
  const store = createStore();
  store.dispatch("librarySearch", { query: "stainless steel 316", ids: [], suggested: ["ss-a", "ss-f"] });
  assert.deepEqual(store.state.library.found, []);
  assert.deepEqual(store.state.library.suggested, ["ss-a", "ss-f"]);
  store.dispatch("librarySearch", { query: "gold", ids: ["Au"] });
  assert.deepEqual([store.state.library.found, store.state.library.suggested], [["Au"], []]);
  store.dispatch("librarySearch", { query: " ", ids: null, suggested: ["x"] });
  assert.deepEqual([store.state.library.found, store.state.library.suggested], [null, []]);
});
