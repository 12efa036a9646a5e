// The curve editor: pick a material, edit its RGB reflectance curves at one
// or more coating indices, refit on the service (POST /fits/from-curves),
// see the fit, its preview and its error map, save and download it.
//
// Curves and metrics come from the service; the preview runs the project's
// own GLSL in WebGL2 (preview.js), so the model has one definition per
// language. Refits run while a point is dragged: one request in flight, the
// latest edit sent next, answers older than the one shown dropped; the fit
// id, figures, curves and preview always show the same fit (present()).

import * as api from "./api.js";
import { drawErrorMap } from "./heatmap.js";
import { ReflectancePlot } from "./plot.js";
import { ENVIRONMENT, PANEL, ShaderBall } from "./preview.js";

const SAMPLES = 46; // 0, 2, ..., 90 degrees
const HANDLES = [0, 20, 36, 50, 60, 70, 78, 84];
const FALLOFF_DEG = 9; // width of the bump a dragged point makes
const RETRY_MS = [250, 500, 1000, 2000, 4000]; // backoff after a 503 (or Retry-After)
const LAST_KEY = "coated-editor-material"; // localStorage: the material open last

const $ = (id) => document.getElementById(id);

const state = {
  base: null,       // the fit being edited (its curves are the starting point)
  fit: null,        // the fit on screen (id, figures, curves and preview)
  eta: 1.5,
  edits: {},        // eta_i (2 decimals) -> target rgb, SAMPLES x 3
  undo: [],
  redo: [],
  theta: [],
  baseCurves: null, // reference, lazanyi and base model at the current eta_i
  model: null,      // the fit on screen at the current eta_i
  etaRequest: 0,    // drops curves of superseded eta_i (or fits)
};

// The refit pipeline: `wanted` is the latest edit not yet sent; one request
// in flight at a time; `shown` is the sequence number of the answer on
// screen, and an answer older than it is dropped.
const live = { wanted: null, inFlight: false, seq: 0, shown: 0, attempt: 0, waiters: [], timer: null, failed: null };

// Timings for benchmarks/editor_speed.py: when the last edit happened, and
// for each fit shown, the edit it answers and when its curve and its first
// preview frame were drawn (performance.now(), ms).
const telemetry = { lastEditAt: 0, shown: [] };
window.cfTelemetry = telemetry;

const plot = new ReflectancePlot($("plot"), { onDrag: drag, onDragEnd: dragEnd });
let ball = null; // the WebGL2 preview, once its shaders compiled

// ---------------------------------------------------------------- messages

// `kind` tags a message so that it can be cleared by what resolves it
// ("retry": cleared by the next answer).
function sayUpload(text, ok = false) {
  const box = $("upload-message");
  box.textContent = text;
  box.classList.toggle("ok", ok);
}

function say(text, ok = false, kind = "") {
  const box = $("message");
  box.textContent = text;
  box.classList.toggle("ok", ok);
  box.dataset.kind = text ? kind : "";
}

// A refusal, shown; a 401 (the service wants its API token) opens the token
// field and remembers `retry`, run again once a token is entered.
let retryAfterToken = null;
function report(error, retry = null, prefix = "") {
  if (error.status !== 401) {
    say(prefix + error.message);
    return;
  }
  retryAfterToken = retry;
  $("token-settings").open = true;
  $("token").focus();
  say(`${prefix}The service needs its API token (401). Enter it under “API token” ` +
    `and press Use token${retry ? "; the action is then retried" : ""}.`);
}

function guard(work) {
  const run = (...args) => Promise.resolve(work(...args)).catch((error) => report(error, () => run(...args)));
  return run;
}

let busyCount = 0;
async function busy(text, work) {
  busyCount += 1;
  $("busy-text").textContent = text;
  $("busy").hidden = false;
  document.body.setAttribute("aria-busy", "true");
  try {
    return await work();
  } finally {
    busyCount -= 1;
    if (busyCount === 0) {
      $("busy").hidden = true;
      document.body.removeAttribute("aria-busy");
    }
  }
}

// "updating…" on the preview and plot while the fit on screen is not the
// fit of the edits on screen.
function updating(on) {
  $("preview-state").hidden = !on;
  document.querySelector(".side").classList.toggle("updating", on);
  $("plot").classList.toggle("updating", on);
}

// ---------------------------------------------------------------- materials

async function loadMaterials(select = null) {
  const { materials } = await api.listMaterials();
  const picker = $("material");
  picker.replaceChildren();
  const groups = { library: "Library", saved: "Saved" };
  const nodes = {};
  for (const [key, label] of Object.entries(groups)) {
    nodes[key] = document.createElement("optgroup");
    nodes[key].label = label;
    picker.appendChild(nodes[key]);
  }
  for (const m of materials) {
    const option = document.createElement("option");
    const saved = m.kind !== "library";
    option.value = saved ? `saved:${m.id}` : `library:${m.id}`;
    option.textContent = saved ? `${m.name} (${m.kind === "curves" ? "edited" : "n, k"})` : m.name;
    option.dataset.source = m.source || "";
    nodes[saved ? "saved" : "library"].appendChild(option);
  }
  if (!nodes.saved.children.length) nodes.saved.remove();
  if (select) picker.value = select;
}

// The fit of a material-picker value (a library fit is made or served from the store).
async function fitOf(value) {
  const [kind, id] = value.split(/:(.*)/s);
  if (kind === "library") return api.fitLibrary(id, [1.0, 2.5]);
  const material = await api.getMaterial(id);
  return material.latest_fit;
}

async function pickMaterial(value, pending = null) {
  if (!value) return;
  await busy("Fitting the material…", async () => setBase(await (pending || fitOf(value))));
}

// Cold start: the first fit's curves and reference texture, asked for as
// soon as the fit is known, while the preview's shaders still compile.
const prefetched = new Map(); // fit id -> { eta, curves, texture } promises

function prefetch(fit) {
  const early = {
    eta: state.eta,
    curves: api.curves(fit.id, state.eta, SAMPLES),
    texture: fit.has_nk ? api.referenceTexture(fit.id) : null,
  };
  for (const promise of [early.curves, early.texture]) if (promise) promise.catch(() => {}); // used, or asked again
  prefetched.set(fit.id, early);
}

async function setBase(fit) {
  state.base = fit;
  state.savedId = null;
  state.edits = {};
  state.undo = [];
  state.redo = [];
  live.wanted = null;
  live.shown = ++live.seq; // answers for the previous material are dropped
  const [lo, hi] = fit.eta_i_range;
  const slider = $("eta");
  slider.min = lo;
  slider.max = hi;
  slider.disabled = hi <= lo;
  state.eta = Math.min(hi, Math.max(lo, state.eta));
  slider.value = state.eta;
  $("name").value = fit.kind === "curves" ? fit.name : `${fit.name} edited`;
  $("material-source").textContent = fit.source ? fit.source.split("\n")[0].slice(0, 160) : "";
  $("compare").disabled = !fit.has_nk;
  $("reset").title = fit.kind === "curves" ? "Back to the saved edit as opened" : "Back to the measured data";
  say("");
  const early = prefetched.get(fit.id);
  prefetched.clear();
  const curves$ = early && early.eta === state.eta ? early.curves : api.curves(fit.id, state.eta, SAMPLES);
  const [curves] = await Promise.all([curves$, loadReference(fit, early && early.texture)]);
  state.baseCurves = curves;
  state.theta = curves.theta_deg.map((t) => Math.round(t * 1e6) / 1e6);
  present(fit, curves);
}

// The spectral reference texture of the base (its measured n, k) for the
// preview; fits without n, k show the model alone.
async function loadReference(fit, pending = null) {
  if (!ball || !fit.has_nk) {
    applyPanels();
    return;
  }
  try {
    ball.setReference(await (pending || api.referenceTexture(fit.id)));
  } catch (error) {
    say(`Spectral reference unavailable: ${error.message}`);
  }
  applyPanels();
}

function applyPanels() {
  if (!ball) return;
  const split = state.base && state.base.has_nk ? $("compare").value : "none";
  const panels = {
    all: [PANEL.model, PANEL.lazanyi, PANEL.reference],
    reference: [PANEL.model, PANEL.reference],
    lazanyi: [PANEL.model, PANEL.lazanyi],
    none: [PANEL.model],
  }[split];
  ball.set({ panels });
}

// ---------------------------------------------------------------- curves

const key = (eta) => Number(eta).toFixed(2);

// The curves an edit starts from: the measured reference, or for a saved
// edit (a curve fit) its own model, so that editing it again starts from it.
function target() {
  const edit = state.edits[key(state.eta)];
  if (edit) return edit;
  if (!state.baseCurves) return null;
  if (state.base.kind === "curves") return state.baseCurves.model;
  return state.baseCurves.reference || state.baseCurves.model;
}

// The curves at the current eta_i: the base's (reference, Lazanyi) and the
// shown fit's model.
async function showEta() {
  $("eta-value").textContent = key(state.eta);
  const request = ++state.etaRequest;
  const fit = state.fit;
  const [base, current] = await Promise.all([
    api.curves(state.base.id, state.eta, SAMPLES),
    fit.id === state.base.id ? null : api.curves(fit.id, state.eta, SAMPLES),
  ]);
  if (request !== state.etaRequest || fit !== state.fit) return; // a later eta_i (or fit) since
  state.theta = base.theta_deg.map((t) => Math.round(t * 1e6) / 1e6);
  state.baseCurves = base;
  state.model = current ? current.model : base.model;
  redraw();
}

function redraw() {
  if (!state.baseCurves) return;
  const edited = Boolean(state.edits[key(state.eta)]);
  $("plot").dataset.eta = key(state.eta);
  plot.draw({
    theta: state.theta,
    reference: state.baseCurves.reference || state.baseCurves.model,
    target: target(),
    model: state.model,
    lazanyi: $("show-lazanyi").checked ? state.baseCurves.lazanyi_adjusted : null,
    handles: HANDLES,
    criticalDeg: state.eta > 1 ? (Math.asin(1 / state.eta) * 180) / Math.PI : null,
    channel: document.querySelector("input[name=channel]:checked").value,
    edited,
  });
  const etas = Object.keys(state.edits).sort();
  const list = $("edited-etas");
  list.replaceChildren();
  if (!etas.length) {
    list.textContent = "No edits yet.";
  } else {
    list.append("Edited at ηᵢ: ");
    for (const eta of etas) {
      const button = document.createElement("button");
      button.type = "button";
      button.className = "chip";
      button.textContent = eta;
      button.setAttribute("aria-label", `Go to the edit at eta_i ${eta}`);
      button.addEventListener("click", () => setEta(Number(eta)));
      list.append(button, " ");
    }
  }
  $("undo").disabled = !state.undo.length;
  $("redo").disabled = !state.redo.length;
  $("reset").disabled = !etas.length;
  $("save").disabled = !etas.length;
  showDirty();
}

function snapshot() {
  return JSON.stringify(state.edits);
}

let dragStart = null;
let pointerDrag = false; // a pointer is dragging a point: refits are live

// Move a control point; true when the target changed (a refit follows at
// once, throttled by the pipeline).
function drag(channel, handle, value, pointer = false) {
  const k = key(state.eta);
  // The slider moved and its curves are not in yet: the plot shows another eta_i.
  if (!state.baseCurves || key(state.baseCurves.eta_i) !== k) return false;
  // Clamped: the reference can exceed 1 by rounding (1.0000000000000002 at 90 degrees).
  const current = target().map((rgb) => rgb.map((v) => Math.min(1, Math.max(0, v))));
  const i = state.theta.indexOf(HANDLES[handle]);
  const before = current[i][channel];
  if (value === before) return false;
  if (dragStart === null) dragStart = snapshot();
  pointerDrag = pointer;
  const all = document.querySelector("input[name=channel]:checked").value === "all";
  const at = (t) => Math.exp(-0.5 * ((t - HANDLES[handle]) / FALLOFF_DEG) ** 2) * (1 - (t / 90) ** 6);
  const peak = at(HANDLES[handle]);
  // One channel: the point moves by delta and its neighbours by less. All
  // three: the three channels are scaled (brightness changes, hue stays),
  // by value / before at the point and proportionally less around it.
  const delta = value - before;
  const ratio = before > 1e-6 ? value / before : null;
  for (let j = 0; j < state.theta.length; j++) {
    // Grazing (90 degrees) stays 1: the model meets 1 there whatever its coefficients.
    const w = at(state.theta[j]) / peak;
    if (all) {
      const scale = ratio === null ? null : 1 + (ratio - 1) * w;
      for (let c = 0; c < 3; c++) {
        const next = scale === null ? current[j][c] + delta * w : current[j][c] * scale;
        current[j][c] = Math.min(1, Math.max(0, next));
      }
    } else {
      current[j][channel] = Math.min(1, Math.max(0, current[j][channel] + delta * w));
    }
  }
  state.edits[k] = current;
  telemetry.lastEditAt = performance.now();
  redraw();
  requestRefit();
  return true;
}

function dragEnd() {
  pointerDrag = false;
  if (dragStart !== null) {
    if (dragStart !== snapshot()) {
      state.undo.push(dragStart);
      state.redo = [];
    }
    dragStart = null;
  }
  redraw();
  requestRefit();
}

// ---------------------------------------------------------------- refits

// A refit of `edits`: a draft unless saved; while a point is dragged, a live
// refit (one short solve started from the fit on screen, fast enough to
// follow the pointer), replaced by a full refit on release.
function requestBody(edits, draft = true, startFit = null) {
  const etas = Object.keys(edits).sort();
  const body = {
    name: $("name").value.trim() || "edited",
    base: { fit: state.base.id },
    curves: etas.map((eta) => ({ eta_i: Number(eta), angle_deg: state.theta, rgb: edits[eta] })),
    draft,
  };
  if (startFit) Object.assign(body, { live: true, start_fit: startFit });
  return body;
}

// Ask for a fit of the edits on screen; the answer shows when it comes
// (await whenFitted() for it).
function requestRefit() {
  live.wanted = snapshot();
  live.failed = null;
  updating(true);
  pump();
}

const sleep = (ms) => new Promise((resolve) => { live.timer = setTimeout(resolve, ms); });

async function pump() {
  if (live.inFlight || live.wanted === null) return;
  const wanted = live.wanted;
  const edits = JSON.parse(wanted);
  const base = state.base;
  const editAt = telemetry.lastEditAt;
  // Live while a pointer drags a point, from the fit on screen (of this base).
  const startFit = pointerDrag ? (state.fit || base).id : null;
  live.wanted = null;
  live.inFlight = true;
  const seq = ++live.seq;
  let delay = 0;
  try {
    await busy("Fitting…", async () => {
      const sentAt = performance.now();
      const curvesAt = { etaI: state.eta, samples: SAMPLES };
      const fit = Object.keys(edits).length ? await api.fitFromCurves(requestBody(edits, true, startFit), curvesAt) : base;
      const fittedAt = performance.now();
      const curves = fit.curves && key(fit.curves.eta_i) === key(curvesAt.etaI)
        ? fit.curves : await api.curves(fit.id, state.eta, SAMPLES);
      live.attempt = 0;
      if ($("message").dataset.kind === "retry") say("");
      if (seq > live.shown && base === state.base) {
        live.shown = seq;
        // Recorded before present(): the preview draws the new fit at once, in it.
        const shown = { fit: fit.id, editAt, sentAt, fittedAt, curveAt: null, frameAt: null,
                        live: !!startFit, serverMs: fit.timings ? 1e3 * fit.timings.total : null };
        telemetry.shown.push(shown);
        if (telemetry.shown.length > 1000) telemetry.shown.shift();
        present(fit, curves, wanted);
        shown.curveAt = performance.now();
      }
    });
  } catch (error) {
    if (error.status === 503 && base === state.base && live.attempt < RETRY_MS.length) {
      // Busy: the same edit (unless a newer one is waiting) again, later.
      delay = error.retryAfter ? error.retryAfter * 1000 : RETRY_MS[Math.min(live.attempt, RETRY_MS.length - 1)];
      live.attempt += 1;
      if (live.wanted === null) live.wanted = wanted;
      say(`The service is busy; retrying in ${(delay / 1000).toFixed(1)} s…`, false, "retry");
    } else if (base === state.base) {
      live.failed = error;
      live.attempt = 0;
      report(error, requestRefit, "The service refused the edit: ");
    }
  } finally {
    if (delay) await sleep(delay);
    live.inFlight = false;
  }
  if (live.wanted !== null) {
    pump();
  } else {
    if (!live.failed) updating(false);
    const waiters = live.waiters.splice(0);
    for (const resolve of waiters) resolve(!live.failed && state.fit && live.shownEdits === snapshot());
  }
}

// Resolves once no refit is pending: true when the fit on screen is the fit
// of the edits on screen.
function whenFitted() {
  if (!live.inFlight && live.wanted === null) return Promise.resolve(!live.failed && live.shownEdits === snapshot());
  return new Promise((resolve) => live.waiters.push(resolve));
}

// ---------------------------------------------------------------- fit views

// Everything that names a fit is set here, together: id, figures,
// coefficients, curve, download and preview.
function present(fit, curves, edits = "{}") {
  state.fit = fit;
  live.shownEdits = edits;
  const edited = fit.kind === "curves";
  const model = (fit.metrics.details && fit.metrics.details.target) || fit.metrics.model || {};
  $("de-label").firstChild.textContent = edited ? "Fit vs edited curves, mean ΔE" : "Fit vs measured reference, mean ΔE";
  $("de-mean").textContent = model.delta_E_mean != null ? model.delta_E_mean.toFixed(3) : "–";
  $("fit-id").textContent = fit.id;
  const rows = ["F0", "a", "alpha"].map((p) =>
    `${p.padEnd(5)} ` + fit.coefficients[p].map((row, c) => `${"RGB"[c]} [${row.map((v) => v.toFixed(5)).join(", ")}]`).join("  "));
  $("coefficients").textContent = `degree ${fit.degree}, eta_i in [${fit.eta_i_range.join(", ")}]\n${rows.join("\n")}`;
  const download = $("download");
  download.href = api.packURL(fit.id, $("format").value);
  download.setAttribute("aria-disabled", "false");
  download.setAttribute("download", "");
  if (key(curves.eta_i) === key(state.eta)) {
    state.model = curves.model;
    redraw();
  } else {
    showEta().catch((error) => say(error.message));
  }
  if (ball) ball.setFit(fit);
  warnIfUnfollowable(fit);
  showDirty();
  scheduleErrorMap();
}

// ---------------------------------------------------------------- reach

// An edit is beyond what the model can follow when the fit misses the
// blended target by more than this (Delta E 2000) somewhere.
const REACH_DE = 3.0;

function warnIfUnfollowable(fit) {
  const box = $("reach");
  const target = fit.kind === "curves" && fit.metrics.details && fit.metrics.details.target;
  if (!target || target.delta_E_max <= REACH_DE) {
    box.hidden = true;
    return;
  }
  $("reach-text").textContent =
    `The model cannot follow this edit everywhere: it misses the edited curves by up to ` +
    `ΔE ${target.delta_E_max.toFixed(1)} at ${target.at_theta_deg.toFixed(0)}° and ` +
    `ηᵢ ${target.at_eta_i.toFixed(2)} (1 is a just-visible difference). The fit stays a valid ` +
    `reflectance (0 to 1); the curve shows what you will get.`;
  box.hidden = false;
}

// "Make it gentler": every edit moved halfway back to where it started (undoable).
function gentler() {
  if (!state.baseCurves) return;
  state.undo.push(snapshot());
  state.redo = [];
  const from = state.base.kind === "curves" ? "model" : "reference";
  const etas = Object.keys(state.edits);
  Promise.all(etas.map((eta) => api.curves(state.base.id, Number(eta), SAMPLES))).then((bases) => {
    etas.forEach((eta, k) => {
      const start = bases[k][from] || bases[k].model;
      state.edits[eta] = state.edits[eta].map((rgb, j) =>
        rgb.map((v, c) => Math.min(1, Math.max(0, start[j][c] + 0.5 * (v - start[j][c])))));
    });
    redraw();
    requestRefit();
  }).catch((error) => say(error.message));
}

// ---------------------------------------------------------------- saved state

// Unsaved: there are edits and the fit on screen is not the one last saved
// (a refit is a draft; only Save stores it under the name).
function unsaved() {
  return Object.keys(state.edits).length > 0 && state.fit && state.savedId !== state.fit.id;
}

function showDirty() {
  $("save-state").textContent = unsaved() ? "Unsaved changes (drafts are not saved)" :
    (state.savedId && state.fit && state.savedId === state.fit.id ? "Saved" : "");
  document.body.dataset.unsaved = unsaved() ? "true" : "false";
}

// The heat map costs a request: drawn for the fit on screen once refits pause.
let mapTimer = null;
function scheduleErrorMap() {
  clearTimeout(mapTimer);
  mapTimer = setTimeout(() => {
    if (live.inFlight || live.wanted !== null) return scheduleErrorMap();
    showErrorMap().catch(() => {});
  }, 150);
}

async function showErrorMap() {
  const fit = state.fit;
  try {
    const map = await api.errorMap(fit.id);
    if (fit !== state.fit) return;
    drawErrorMap($("heatmap"), map);
    $("heatmap").dataset.fit = fit.id;
    $("heatmap-caption").textContent = `Against the ${map.against}; dark is close, bright is a visible difference.`;
  } catch (error) {
    $("heatmap-caption").textContent = `Error map unavailable: ${error.message}`;
  }
}

// ---------------------------------------------------------------- actions

let etaTimer = null;
function setEta(eta) {
  state.eta = eta;
  $("eta").value = eta;
  $("eta-value").textContent = key(eta);
  if (ball) ball.set({ eta });
  clearTimeout(etaTimer);
  etaTimer = setTimeout(() => {
    showEta().catch((error) => say(error.message));
  }, 120);
}

async function undoRedo(from, to) {
  if (!from.length) return;
  to.push(snapshot());
  state.edits = JSON.parse(from.pop());
  redraw();
  requestRefit();
  await whenFitted();
}

async function reset() {
  state.undo.push(snapshot());
  state.redo = [];
  state.edits = {};
  redraw();
  requestRefit();
  await whenFitted();
}

async function save() {
  const name = $("name").value.trim();
  if (!name) {
    say("Give the material a name first.");
    $("name").focus();
    return;
  }
  if (!Object.keys(state.edits).length) {
    say("Nothing to save: edit a curve first.");
    return;
  }
  // Saving under the name of another saved material replaces its latest fit: asked first.
  const { materials } = await api.listMaterials();
  const clash = materials.find((m) => m.kind === "curves" && m.name === name);
  const opened = state.base.kind === "curves" && state.base.name === name;
  if (clash && !opened && !window.confirm(`A saved material is called “${name}”. Replace it with this edit?`)) {
    say("Not saved: choose another name, or Save again and confirm to replace it.");
    $("name").focus();
    return;
  }
  requestRefit();
  // A refused refit (401, 422) is reported by the pipeline: nothing was saved.
  if (!(await whenFitted())) {
    if (live.failed) say(`Not saved: ${live.failed.message}`);
    return;
  }
  let fit;
  try {
    fit = await busy("Saving…", () => api.fitFromCurves(requestBody(state.edits, false)));
  } catch (error) {
    report(error, save, "Not saved: ");
    return;
  }
  state.savedId = fit.id;
  const opening = `saved:${fit.material_id}`;
  await loadMaterials(opening);
  remember(opening);
  showDirty();
  say(`Saved “${fit.name}”: it is in the material list (Saved) and survives restarts.`, true);
}

function remember(value) {
  try {
    localStorage.setItem(LAST_KEY, value);
  } catch (_) {
    // storage disabled: the editor opens Au next time
  }
}

async function upload(file) {
  await busy("Fitting the uploaded n, k…", async () => {
    const fit = await api.uploadNK(file, $("upload-name").value.trim());
    await loadMaterials(`saved:${fit.material_id}`);
    remember(`saved:${fit.material_id}`);
    await setBase(fit);
    sayUpload(`Fitted “${fit.name}” from ${file.name}; saved under that name.`, true);
  });
}

function previewSettings() {
  $("exposure-value").textContent = Number($("exposure").value).toFixed(1);
  $("roughness-value").textContent = Number($("roughness").value).toFixed(2);
  $("coat-roughness-value").textContent = Number($("coat-roughness").value).toFixed(2);
  $("coat-roughness").disabled = !$("coat").checked;
  if (!ball) return;
  ball.set({
    environment: ENVIRONMENT[$("environment").value], exposure: Number($("exposure").value),
    roughness: Number($("roughness").value), coated: $("coat").checked, coatRoughness: Number($("coat-roughness").value),
  });
  applyPanels();
}

$("token").value = api.getToken();
$("token-form").addEventListener("submit", (event) => {
  event.preventDefault();
  api.setToken($("token").value.trim());
  say(api.getToken() ? "API token set for this tab." : "API token cleared.", true);
  const retry = retryAfterToken;
  retryAfterToken = null;
  if (retry) guard(retry)();
});
let pickedValue = null; // the material open, to return to when a switch is cancelled
$("material").addEventListener("change", guard(async (event) => {
  const value = event.target.value;
  if (unsaved() && !window.confirm("Discard the unsaved edits of this material?")) {
    event.target.value = pickedValue;
    return;
  }
  await pickMaterial(value);
  pickedValue = value;
  remember(value);
}));
$("upload").addEventListener("change", (event) => {
  const file = event.target.files[0];
  if (!file) return;
  sayUpload("");
  upload(file).catch((error) => {
    if (error.status === 401) report(error, () => upload(file));
    else sayUpload(`Not uploaded: ${error.message}`);
  });
});
$("reach-gentler").addEventListener("click", gentler);
window.addEventListener("beforeunload", (event) => {
  if (!unsaved()) return;
  event.preventDefault();
  event.returnValue = "";
});
$("eta").addEventListener("input", (event) => setEta(Number(event.target.value)));
$("show-lazanyi").addEventListener("change", redraw);
for (const radio of document.querySelectorAll("input[name=channel]")) radio.addEventListener("change", redraw);
$("undo").addEventListener("click", guard(() => undoRedo(state.undo, state.redo)));
$("redo").addEventListener("click", guard(() => undoRedo(state.redo, state.undo)));
$("reset").addEventListener("click", guard(reset));
$("save").addEventListener("click", guard(save));
for (const id of ["compare", "environment", "exposure", "roughness", "coat", "coat-roughness"]) {
  $(id).addEventListener("input", previewSettings);
}
$("format").addEventListener("change", () => {
  if (state.fit) $("download").href = api.packURL(state.fit.id, $("format").value);
});
$("download").addEventListener("click", (event) => {
  if (!state.fit) event.preventDefault();
});
document.addEventListener("keydown", (event) => {
  if (!(event.ctrlKey || event.metaKey) || event.target.matches("input[type=text], input[type=password]")) return;
  const k = event.key.toLowerCase();
  if (k === "z" && !event.shiftKey) { event.preventDefault(); guard(() => undoRedo(state.undo, state.redo))(); }
  if ((k === "z" && event.shiftKey) || k === "y") { event.preventDefault(); guard(() => undoRedo(state.redo, state.undo))(); }
});

// The preview's shaders compile while the material list and first fit load.
const preview = ShaderBall.create($("preview"), $("preview-labels"), $("preview-lighting")).then((made) => {
  ball = made;
  window.cfPreview = made; // for the parity tests and benchmarks
  ball.onFrame = (drawn) => {
    const last = telemetry.shown[telemetry.shown.length - 1];
    if (last && last.fit === drawn.fitId && last.frameAt === null) last.frameAt = performance.now();
  };
  previewSettings();
  ball.set({ eta: state.eta });
  return made;
}).catch((error) => {
  const box = $("preview-error");
  box.hidden = false;
  box.textContent = `The real-time preview is unavailable: ${error.message}`;
  return null;
});

guard(async () => {
  let last = null;
  try {
    last = localStorage.getItem(LAST_KEY);
  } catch (_) {
    // storage disabled
  }
  // Cold start: the material list, the first fit and the preview's shaders
  // load at the same time.
  const wanted = last || "library:Au";
  const first = fitOf(wanted);
  first.then(prefetch, () => {}); // a failure is reported below, if the fit is used
  await loadMaterials();
  const picker = $("material");
  picker.value = wanted;
  const found = picker.value === wanted;
  if (!found) picker.value = "library:Au"; // the remembered material is gone
  await preview;
  await pickMaterial(picker.value, found ? first : null);
  pickedValue = picker.value;
  document.body.dataset.ready = "true";
})();
