// The refit pipeline of the editor: what to send when. Pure transitions on
// a small pipeline value, and a driver that runs them against injected I/O
// (no DOM, no fetch: node --test runs it, tests/static/js/refit.test.mjs).
//
// The rules (docs/editor.md, "Live editing"):
//   - one refit request in flight at a time;
//   - a stale full refit never blocks a new one: a full refit in flight
//     whose edits are no longer the latest is aborted (the service cancels
//     its job when the request goes away) as soon as newer edits exist, and
//     the latest is sent when it settles; a full refit of the very edits
//     already in flight as one is not asked again;
//   - a full refit may be asked while a pointer drags (`full`: the pointer
//     rests on a point), so that it is under way, or done, at the release;
//   - coalescing: an edit made meanwhile waits as `wanted`, and only the
//     latest is sent when the request in flight answers (intermediate edits
//     are never sent);
//   - live vs full: while a pointer drags a point the refit is live (one
//     short solve from the fit on screen, `start_fit`), otherwise full; the
//     choice is made when the request is sent;
//   - stale answers dropped: an answer older than the one on screen, or for
//     a base no longer open, is not shown;
//   - a 503 is retried with backoff (Retry-After, else RETRY_MS), the same
//     edit unless a newer one is waiting; after RETRY_MS.length refusals it
//     is reported, as any other refusal.

import { defaultModelKind } from "../kinds.js";

export const RETRY_MS = [250, 500, 1000, 2000, 4000];

/** A fresh pipeline: nothing wanted, nothing in flight. */
export function initialPipeline() {
  return { wanted: null, full: false, inFlight: null, seq: 0, shown: 0, attempt: 0, failed: null };
}

/** Whether nothing is in flight and nothing waits. */
export const idle = (p) => p.inFlight === null && p.wanted === null;

/**
 * Ask for a refit of `wanted` (the edits' snapshot, a string); it replaces
 * any edit still waiting. `full`: a full refit whatever the context when it
 * is sent (else the context decides, take()); a full refit of `base` for
 * the edits already in flight as a full refit of that base waits for that
 * one's answer instead (nothing waits), unless that one was refused and
 * waits to be retried.
 */
export function want(p, wanted, { full = false, base } = {}) {
  const f = p.inFlight;
  if (full && f !== null && !f.refused && f.startFit === null && f.wanted === wanted
      && (base === undefined || f.base === base)) {
    return { ...p, wanted: null, full: false, failed: null };
  }
  return { ...p, wanted, full, failed: null };
}

/** Whether the request in flight is a full refit of edits other than `wanted` (to abort: it is stale). */
export const stale = (p, wanted) => p.inFlight !== null && p.inFlight.startFit === null && p.inFlight.wanted !== wanted;

/**
 * Take the waiting edit for sending: `{p, job}`, job = {seq, wanted, base,
 * startFit, editAt} from `context` ({base, startFit, editAt}: the base
 * open and, while a pointer drags, the fit to start a live refit from, null
 * for an edit asked as a full refit); job null when a request is in flight
 * or nothing waits.
 */
export function take(p, context) {
  if (p.inFlight !== null || p.wanted === null) return { p, job: null };
  const job = { seq: p.seq + 1, wanted: p.wanted, base: context.base,
                startFit: p.full ? null : context.startFit ?? null, editAt: context.editAt ?? 0 };
  return { p: { ...p, wanted: null, full: false, inFlight: job, seq: job.seq }, job };
}

/**
 * The answer to `job` came, while `baseNow` is open: `{p, show}`, show
 * true when it is newer than the fit on screen and of the base open.
 * The job stays in flight until settle().
 */
export function answered(p, job, baseNow) {
  const show = job.seq > p.shown && job.base === baseNow;
  return { p: { ...p, attempt: 0, shown: show ? job.seq : p.shown }, show };
}

/** The delay before retrying after `error` (a 503), the `attempt`-th retry (0 first). */
export function retryDelay(error, attempt) {
  if (error.retryAfter) return error.retryAfter * 1000;
  return RETRY_MS[Math.min(attempt, RETRY_MS.length - 1)];
}

/**
 * `job` was refused with `error` while `baseNow` is open: `{p, retryMs,
 * report}`. A 503 of the open base, retried fewer than RETRY_MS.length
 * times, waits retryMs and sends the same edit again unless a newer one
 * waits; another refusal of the open base is reported (`failed`); one of a
 * base no longer open is forgotten.
 */
export function refused(p, job, error, baseNow) {
  const current = job.base === baseNow;
  if (error.status === 503 && current && p.attempt < RETRY_MS.length) {
    const retryMs = retryDelay(error, p.attempt);
    // The job stays in flight through the wait, refused: the same edits asked meanwhile are sent again.
    return { p: { ...p, attempt: p.attempt + 1, wanted: p.wanted ?? job.wanted,
                  inFlight: p.inFlight && { ...p.inFlight, refused: true } }, retryMs, report: false };
  }
  if (!current) return { p, retryMs: 0, report: false };
  return { p: { ...p, attempt: 0, failed: error }, retryMs: 0, report: true };
}

/** The job in flight is done (answered or refused, after any retry delay). */
export function settle(p) {
  return { ...p, inFlight: null };
}

/** A new base opened: nothing waits, and every answer asked for so far is dropped. */
export function dropAnswers(p) {
  const seq = p.seq + 1;
  return { ...p, wanted: null, full: false, seq, shown: seq, attempt: 0, failed: null };
}

/**
 * The request body of a refit of `edits` ({eta key: rgb rows}) over the
 * angles `theta`: a draft unless saved; with `startFit` a live refit from
 * that fit. A fit of a kind other than the default is refitted as its kind
 * (a live refit must be of its start's kind).
 */
export function refitBody({ name, base, theta, edits, draft = true, startFit = null }) {
  const etas = Object.keys(edits).sort();
  const body = {
    name: (name || "").trim() || "edited",
    base: { fit: base.id },
    curves: etas.map((eta) => ({ eta_i: Number(eta), angle_deg: theta, rgb: edits[eta] })),
    draft,
  };
  if (base.model && base.model !== defaultModelKind()) body.model = base.model;
  if (startFit) Object.assign(body, { live: true, start_fit: startFit });
  return body;
}

/**
 * The driver: runs the transitions against `io`:
 *   context() -> {base, startFit, editAt}: read when a job is asked for and when it is taken;
 *   fit(job, signal) -> Promise of the answer to show (rejects with {status, retryAfter, message});
 *     `signal` (an AbortSignal) aborts it once it is stale (its rejection is then forgotten);
 *   show(answer, job): put it on screen (only answers that pass answered());
 *   onAnswer(job): every answer, shown or not (clears a "retrying" message);
 *   onRetry(ms, job), onReport(error, job): a 503's wait, a refusal to report;
 *   onUpdating(on): whether the fit on screen may lag the edits;
 *   sleep(ms) -> Promise, busy(work) -> work's promise (a spinner around a request).
 */
export class RefitPipeline {
  constructor(io) {
    this.io = { onAnswer() {}, onRetry() {}, onReport() {}, onUpdating() {}, busy: (work) => work(),
                sleep: (ms) => new Promise((resolve) => setTimeout(resolve, ms)), ...io };
    this.p = initialPipeline();
    this.waiters = [];
  }

  /**
   * Ask for a refit of `wanted` (a snapshot); the answer shows when it
   * comes. `full`: a full refit even while a pointer drags.
   */
  request(wanted, { full = false } = {}) {
    const context = this.io.context();
    this.p = want(this.p, wanted, { full: full || !context.startFit, base: context.base });
    this.io.onUpdating(true);
    if (this.p.wanted !== null) this.outdate(this.p.wanted);
    this.pump();
  }

  /** The edits are now `wanted` (a live refit in the page, no request): a full refit of others in flight is aborted. */
  outdate(wanted) {
    if (this.controller && stale(this.p, wanted)) this.controller.abort();
  }

  /** A new base opened: forget what waits, drop every answer under way. */
  drop() {
    this.p = dropAnswers(this.p);
  }

  get failed() {
    return this.p.failed;
  }

  /** Whether a request is in flight or waits. */
  get pending() {
    return !idle(this.p);
  }

  /** Resolves with the last refusal (null if none) once nothing is in flight or waits. */
  whenIdle() {
    if (idle(this.p)) return Promise.resolve(this.p.failed);
    return new Promise((resolve) => this.waiters.push(resolve));
  }

  async pump() {
    const taken = take(this.p, this.io.context());
    if (!taken.job) return;
    this.p = taken.p;
    const job = taken.job;
    const controller = (this.controller = new AbortController());
    let retryMs = 0;
    try {
      const answer = await this.io.busy(() => this.io.fit(job, controller.signal));
      const result = answered(this.p, job, this.io.context().base);
      this.p = result.p;
      this.io.onAnswer(job);
      if (result.show) this.io.show(answer, job);
    } catch (error) {
      if (!controller.signal.aborted) { // else stale: newer edits are asked for, and nothing is said
        const result = refused(this.p, job, error, this.io.context().base);
        this.p = result.p;
        retryMs = result.retryMs;
        if (retryMs) this.io.onRetry(retryMs, job);
        if (result.report) this.io.onReport(error, job);
      }
    } finally {
      if (retryMs) await this.io.sleep(retryMs);
      this.p = settle(this.p);
      this.controller = null;
    }
    if (this.p.wanted !== null) {
      this.pump();
      return;
    }
    if (!this.p.failed) this.io.onUpdating(false);
    for (const resolve of this.waiters.splice(0)) resolve(this.p.failed);
  }
}
