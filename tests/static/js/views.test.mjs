// The pure parts of the studio's views: typed entry's check
// (entry_view.js parseTyped), the library's search (library_view.js
// shownLibrary: the service's ?q= answer in its order), links (studio.js linkOf, linkTo)
// and compare mode's figures (compare_view.js compareFigures).

import assert from "node:assert/strict";
import { test } from "node:test";

import { compareFigures } from "../../../static/editor/compare_view.js";
import { parseTyped } from "../../../static/editor/entry_view.js";
import { shownLibrary } from "../../../static/editor/library_view.js";
import { draftExpiry, linkOf, linkTo } from "../../../static/editor/studio.js";

test("parseTyped: a finite number within [lo, hi], else why (naming the rule and the value)", () => {
  assert.deepEqual(parseTyped(" 1.33 ", 1, 2.5, "ηᵢ"), { value: 1.33 });
  assert.deepEqual(parseTyped("2.7", 1, 2.5, "ηᵢ"), { error: "ηᵢ must lie in [1, 2.5], got 2.7." });
  assert.deepEqual(parseTyped("", 0, 1, "A reflectance"), { error: "A reflectance must be a number, got “”." });
  assert.match(parseTyped("Infinity", 0, 1, "x").error, /must be a number/);
  assert.deepEqual(parseTyped("0", 0, 1, "x"), { value: 0 });
});

test("shownLibrary: the service's matches in its order, or every entry", () => {
  const materials = [{ id: "Au" }, { id: "Cu" }, { id: "Al" }];
  const ids = (found) => shownLibrary({ materials, found }).map((m) => m.id);
  assert.deepEqual(ids(null), ["Au", "Cu", "Al"]);
  assert.deepEqual(ids(["Cu", "Au"]), ["Cu", "Au"], "the service's rank, not the list's order");
  assert.deepEqual(ids(["Zz", "Al"]), ["Al"], "an id listed at another eta_i is left out");
  assert.deepEqual(ids([]), []);
});

test("links: ?fit= and the service's ?material=&version=", () => {
  assert.deepEqual(linkOf("?fit=abc"), { fit: "abc" });
  assert.deepEqual(linkOf("?material=m1&version=2"), { material: "m1", version: 2 });
  assert.deepEqual(linkOf("?material=Au"), { material: "Au", version: null });
  assert.equal(linkOf(""), null);
  assert.equal(linkTo("a b", "http://h:1"), "http://h:1/?fit=a%20b");
});

test("compareFigures: none until the other curve is in at this eta_i; then mean and max", () => {
  const theta = [0, 45, 90];
  const mine = [[0.5, 0.4, 0.3], [0.6, 0.5, 0.4], [1, 1, 1]];
  const state = { eta: 1.5, theta, model: mine, compare: { fit: { id: "x" }, model: null, eta: null } };
  assert.equal(compareFigures(state), null);
  state.compare = { fit: { id: "x" }, model: mine, eta: "1.40" };
  assert.equal(compareFigures(state), null, "a curve of another eta_i");
  state.compare.eta = "1.50";
  assert.deepEqual(compareFigures(state), { mean: 0, max: 0, atDeg: 0 });
});

test("draftExpiry: a link to an unsaved edit says it expires and when", () => {
  const expiresAt = Date.UTC(2026, 0, 3, 10, 0) / 1000;  // the link's answer: a day after it was made
  const text = draftExpiry(expiresAt, 86400);
  assert.match(text, /unsaved edit, kept 24 h: it expires 3 Jan 2026/);
  assert.match(text, /Save to keep it/);
  assert.match(draftExpiry(expiresAt, null), /save it to keep the link working/);
  assert.match(draftExpiry(null, 86400), /save it to keep the link working/);
});
