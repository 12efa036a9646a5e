// Every saved material, not the first page only: listAllMaterials follows
// next_cursor to the end (a stub fetch answers three pages), and the saved
// list shows what the service's search found (manage_view.js shownSaved).
import test from "node:test";
import assert from "node:assert/strict";

import { listAllMaterials } from "../../../static/api.js";
import { shownSaved } from "../../../static/editor/manage_view.js";

test("listAllMaterials: every page, each asked with the previous next_cursor", async () => {
  const asked = [];
  const pages = { "": [["a", "b"], 2], 2: [["c", "d"], 4], 4: [["e"], null] };
  globalThis.sessionStorage = { getItem: () => null };
  globalThis.fetch = async (url) => {
    asked.push(url);
    const cursor = new URL(url, "http://x").searchParams.get("cursor") ?? "";
    const [ids, next] = pages[cursor];
    return { ok: true, json: async () => ({ materials: ids.map((id) => ({ id })), next_cursor: next }) };
  };
  const all = await listAllMaterials({ kinds: ["curves"], q: "gold leaf" });
  assert.deepEqual(all.map((m) => m.id), ["a", "b", "c", "d", "e"]);
  assert.equal(asked.length, 3);
  assert.ok(asked.every((url) => url.includes("kind=curves") && url.includes("q=gold+leaf")));
  assert.ok(!asked[0].includes("cursor=") && asked[1].endsWith("cursor=2") && asked[2].endsWith("cursor=4"));
});

test("shownSaved: the materials the service found, in the list's order, or all", () => {
  const saved = [{ id: "m1" }, { id: "m2" }, { id: "m3" }];
  assert.deepEqual(shownSaved(saved, null), saved);
  assert.deepEqual(shownSaved(saved, ["m3", "m1"]).map((m) => m.id), ["m1", "m3"]);
  assert.deepEqual(shownSaved(saved, []), []);
});
