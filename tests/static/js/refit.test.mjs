// The editor's refit pipeline (static/editor/refit.js): the pure
// transitions and the driver against fake I/O (node --test; run from
// pytest by tests/static/test_editor_js.py).

import assert from "node:assert/strict";
import { test } from "node:test";

import "./domain.mjs";

import {
  RETRY_MS, RefitPipeline, answered, dropAnswers, idle, initialPipeline, refitBody, refused, retryDelay,
  settle, stale, take, want,
} from "../../../static/editor/refit.js";

const BASE = { id: "base-fit", model: "coated-conductor" };
const OTHER = { id: "other-fit", model: "coated-conductor" };

test("one request in flight; what waits meanwhile is coalesced to the latest edit", () => {
  let p = want(initialPipeline(), "edit 1");
  const first = take(p, { base: BASE });
  assert.equal(first.job.wanted, "edit 1");
  p = first.p;
  assert.equal(take(p, { base: BASE }).job, null, "nothing is sent while a request is in flight");
  p = want(want(p, "edit 2"), "edit 3");
  assert.equal(take(p, { base: BASE }).job, null);
  p = settle(answered(p, first.job, BASE).p);
  const second = take(p, { base: BASE });
  assert.equal(second.job.wanted, "edit 3", "the latest edit is sent, edit 2 never");
  assert.equal(second.job.seq, first.job.seq + 1);
  p = settle(answered(second.p, second.job, BASE).p);
  assert.ok(idle(p));
  assert.equal(take(p, { base: BASE }).job, null, "nothing left to send");
});

test("live vs full: the start fit is the context's when the job is taken", () => {
  const live = take(want(initialPipeline(), "e"), { base: BASE, startFit: "on-screen" }).job;
  assert.equal(live.startFit, "on-screen");
  const full = take(want(initialPipeline(), "e"), { base: BASE }).job;
  assert.equal(full.startFit, null);
  const body = refitBody({ name: " x ", base: BASE, theta: [0, 2], edits: { "1.50": [[0.5, 0.5, 0.5]] }, startFit: "on-screen" });
  assert.deepEqual({ live: body.live, start_fit: body.start_fit, draft: body.draft, name: body.name },
                   { live: true, start_fit: "on-screen", draft: true, name: "x" });
  const fullBody = refitBody({ name: "", base: BASE, theta: [0, 2], edits: { "1.50": [[0.5, 0.5, 0.5]] } });
  assert.equal(fullBody.live, undefined);
  assert.equal(fullBody.start_fit, undefined);
  assert.equal(fullBody.name, "edited");
});

test("refit bodies: curves sorted by eta_i, the base by id, its kind kept when not the default", () => {
  const edits = { "2.00": [[0.1, 0.2, 0.3]], "1.25": [[0.4, 0.5, 0.6]] };
  const body = refitBody({ name: "n", base: BASE, theta: [10], edits, draft: false });
  assert.deepEqual(body.curves.map((c) => c.eta_i), [1.25, 2]);
  assert.deepEqual(body.curves[0], { eta_i: 1.25, angle_deg: [10], rgb: [[0.4, 0.5, 0.6]] });
  assert.deepEqual(body.base, { fit: "base-fit" });
  assert.equal(body.draft, false);
  assert.equal("model" in body, false, "the default kind adds nothing (ids stay as they were)");
  const rgb = refitBody({ name: "n", base: { id: "r", model: "rgb-conductor" }, theta: [10], edits });
  assert.equal(rgb.model, "rgb-conductor", "an rgb-conductor is refitted as one (a live refit must be)");
});

test("stale answers are dropped: older than the one shown, or of a base no longer open", () => {
  let p = want(initialPipeline(), "a");
  const a = take(p, { base: BASE });
  p = settle(answered(a.p, a.job, BASE).p);
  assert.equal(p.shown, a.job.seq);
  // An answer with a smaller sequence number than the one on screen.
  const old = { ...a.job, seq: a.job.seq - 1 };
  assert.equal(answered(p, old, BASE).show, false);
  // An answer for the previous base, after another was opened.
  p = want(p, "b");
  const b = take(p, { base: BASE });
  p = dropAnswers(b.p);
  assert.equal(answered(p, b.job, OTHER).show, false, "base changed");
  assert.equal(answered(p, b.job, BASE).show, false, "dropAnswers drops what was under way");
  assert.equal(p.wanted, null);
});

test("a 503 is retried with backoff (Retry-After first), the same edit unless a newer waits", () => {
  assert.equal(retryDelay({ status: 503, retryAfter: 2 }, 0), 2000);
  assert.deepEqual([0, 1, 2, 3, 4, 9].map((n) => retryDelay({ status: 503 }, n)), [...RETRY_MS, RETRY_MS[4]]);
  let p = want(initialPipeline(), "e1");
  const job = take(p, { base: BASE });
  let r = refused(job.p, job.job, { status: 503 }, BASE);
  assert.equal(r.retryMs, RETRY_MS[0]);
  assert.equal(r.report, false);
  assert.equal(r.p.wanted, "e1", "the same edit again");
  p = want(job.p, "e2");
  r = refused(p, job.job, { status: 503 }, BASE);
  assert.equal(r.p.wanted, "e2", "a newer edit wins over the retry");
  // After RETRY_MS.length refusals in a row it is reported.
  p = job.p;
  for (let i = 0; i < RETRY_MS.length; i++) p = refused(p, job.job, { status: 503 }, BASE).p;
  r = refused(p, job.job, { status: 503 }, BASE);
  assert.equal(r.report, true);
  assert.equal(r.p.failed.status, 503);
});

test("other refusals are reported, refusals for another base forgotten", () => {
  const job = take(want(initialPipeline(), "e"), { base: BASE });
  const r = refused(job.p, job.job, { status: 422, message: "no" }, BASE);
  assert.equal(r.report, true);
  assert.equal(r.p.failed.message, "no");
  const gone = refused(job.p, job.job, { status: 422 }, OTHER);
  assert.equal(gone.report, false);
  assert.equal(gone.p.failed, null);
  assert.equal(want(r.p, "again").failed, null, "a new request clears the failure");
});

// A fake service: every fit call waits until the test answers it.
function fakeService() {
  const calls = [];
  const io = {
    base: BASE,
    startFit: null,
    shown: [],
    reports: [],
    retries: [],
    updating: [],
    context: () => ({ base: io.base, startFit: io.startFit, editAt: 0 }),
    // As fetch does: an aborted request rejects with an AbortError.
    fit: (job, signal) => new Promise((resolve, reject) => {
      calls.push({ job, resolve, reject, signal });
      signal.addEventListener("abort", () => reject(new DOMException("aborted", "AbortError")));
    }),
    show: (answer, job) => io.shown.push([answer, job.wanted]),
    onReport: (error) => io.reports.push(error),
    onRetry: (ms) => io.retries.push(ms),
    onUpdating: (on) => io.updating.push(on),
    sleep: () => Promise.resolve(),
  };
  return { io, calls };
}

const tick = () => new Promise((resolve) => setImmediate(resolve));

test("the driver: drags coalesce, the answers show in order, whenIdle resolves at the end", async () => {
  const { io, calls } = fakeService();
  const pipeline = new RefitPipeline(io);
  io.startFit = "on-screen"; // a pointer drags
  pipeline.request("d1");
  pipeline.request("d2");
  pipeline.request("d3");
  await tick();
  assert.equal(calls.length, 1, "one request in flight");
  assert.equal(calls[0].job.wanted, "d1");
  assert.equal(calls[0].job.startFit, "on-screen");
  const idle = pipeline.whenIdle();
  assert.ok(pipeline.pending);
  io.startFit = null; // released: the next request is a full refit
  calls[0].resolve("fit 1");
  await tick();
  assert.equal(calls.length, 2);
  assert.equal(calls[1].job.wanted, "d3", "d2 is never sent");
  assert.equal(calls[1].job.startFit, null);
  calls[1].resolve("fit 3");
  assert.equal(await idle, null);
  assert.deepEqual(io.shown, [["fit 1", "d1"], ["fit 3", "d3"]]);
  assert.deepEqual(io.updating, [true, true, true, false]);
  assert.equal(pipeline.pending, false);
});

test("the driver drops an answer for a base no longer open", async () => {
  const { io, calls } = fakeService();
  const pipeline = new RefitPipeline(io);
  pipeline.request("old edit");
  await tick();
  io.base = OTHER;
  pipeline.drop();
  calls[0].resolve("fit of the old base");
  await pipeline.whenIdle();
  assert.deepEqual(io.shown, []);
});

test("the driver retries a 503 and reports a 422 once", async () => {
  const { io, calls } = fakeService();
  const pipeline = new RefitPipeline(io);
  pipeline.request("e");
  await tick();
  calls[0].reject({ status: 503, retryAfter: 0.5 });
  await tick();
  await tick();
  assert.deepEqual(io.retries, [500]);
  assert.equal(calls.length, 2);
  assert.equal(calls[1].job.wanted, "e");
  calls[1].reject({ status: 422, message: "refused" });
  const failed = await pipeline.whenIdle();
  assert.equal(failed.message, "refused");
  assert.equal(io.reports.length, 1);
  assert.equal(io.updating.at(-1), true, "the fit on screen still lags the edits");
});

test("a full refit asked for the edits already in flight as one waits for that answer; a full one asked while dragging is full", () => {
  let p = want(initialPipeline(), "e", { full: true, base: BASE });
  const taken = take(p, { base: BASE, startFit: "on-screen" });
  assert.equal(taken.job.startFit, null, "asked full: full whatever the context");
  p = want(taken.p, "e", { full: true, base: BASE });
  assert.equal(p.wanted, null, "the same edits, already in flight as a full refit: nothing waits");
  assert.equal(stale(p, "e"), false);
  assert.equal(want(taken.p, "e", { full: true, base: OTHER }).wanted, "e", "another base: asked again");
  assert.equal(want(taken.p, "e").wanted, "e", "a live refit of them is still asked");
  assert.equal(stale(want(taken.p, "f"), "f"), true, "a full refit of other edits is stale");
  const live = take(want(initialPipeline(), "e"), { base: BASE, startFit: "on-screen" }).p;
  assert.equal(stale(live, "f"), false, "a live step in flight is never aborted (it is short)");
});

test("the driver aborts a stale full refit at once and sends the latest edits; nothing is reported", async () => {
  const { io, calls } = fakeService();
  const pipeline = new RefitPipeline(io);
  pipeline.request("release 1"); // a full refit (no pointer drags)
  await tick();
  assert.equal(calls.length, 1);
  const idle = pipeline.whenIdle();
  pipeline.request("release 2");
  assert.equal(calls[0].signal.aborted, true, "the stale refit is aborted when newer edits are asked");
  await tick();
  await tick();
  assert.equal(calls.length, 2, "the latest is sent without waiting for the stale one's answer");
  assert.equal(calls[1].job.wanted, "release 2");
  calls[1].resolve("fit 2");
  assert.equal(await idle, null);
  assert.deepEqual(io.shown, [["fit 2", "release 2"]]);
  assert.deepEqual(io.reports, [], "an aborted refit is not a refusal");
  assert.deepEqual(io.retries, []);
});

test("the driver: a full refit at rest during a drag is not asked again at the release; a move aborts it", async () => {
  const { io, calls } = fakeService();
  const pipeline = new RefitPipeline(io);
  io.startFit = "on-screen"; // a pointer drags (its live steps are solved in the page)
  pipeline.request("rest 1", { full: true });
  await tick();
  assert.equal(calls[0].job.startFit, null, "a full refit while the pointer drags");
  pipeline.outdate("rest 1");
  assert.equal(calls[0].signal.aborted, false, "the same edits: kept");
  pipeline.outdate("moved");
  assert.equal(calls[0].signal.aborted, true, "the pointer moved on: aborted");
  await tick();
  pipeline.request("moved", { full: true }); // at rest again
  await tick();
  assert.equal(calls.length, 2);
  io.startFit = null; // released where it rested
  pipeline.request("moved");
  await tick();
  assert.equal(calls.length, 2, "the release's refit is the one under way");
  calls[1].resolve("fit at rest");
  await pipeline.whenIdle();
  assert.deepEqual(io.shown, [["fit at rest", "moved"]]);
});

test("a full refit refused with a 503 is sent again after its wait, even when its edits are asked meanwhile", async () => {
  const { io, calls } = fakeService();
  let wake;
  io.sleep = () => new Promise((resolve) => { wake = resolve; });
  const pipeline = new RefitPipeline(io);
  pipeline.request("e");
  await tick();
  calls[0].reject({ status: 503, retryAfter: 1 });
  await tick();
  pipeline.request("e"); // the same edits, asked while the refused one waits for its retry
  wake();
  await tick();
  await tick();
  assert.equal(calls.length, 2, "sent again after the wait");
  assert.equal(calls[1].job.wanted, "e");
  calls[1].resolve("fit e");
  await pipeline.whenIdle();
  assert.deepEqual(io.shown, [["fit e", "e"]]);
});
