// The curve editor: pick a material, edit its RGB reflectance curves at one
// or more coating indices, refit on the service (POST /fits/from-curves),
// see the fit, its preview and its error map, save and download it.
//
// This module only composes the parts in static/editor/ (docs/editor.md,
// "The editor's modules"): the state (state.js, one object changed by named
// actions), the refit pipeline (refit.js: what is sent when, stale answers
// dropped), the views that render from the state (plot_view.js,
// preview_view.js, readout.js, messages.js) and the material picker
// (materials.js). The fit id, figures, curves and preview always show the
// same fit: present() sets them from one answer.

import * as api from "./api.js";
import { modelKind, modelKindsKnown, setModelKinds } from "./kinds.js";
import { colourRows, coloursOf } from "./editor/colour.js";
import { ColourView } from "./editor/colour_view.js";
import { bindPageInputs, mayDiscard } from "./editor/inputs.js";
import { fitOf, FIRST, loadMaterials, prefetch, recall, remember, savedVersion } from "./editor/materials.js";
import { Messages } from "./editor/messages.js";
import { PlotView } from "./editor/plot_view.js";
import { PreviewView } from "./editor/preview_view.js";
import { SceneView } from "./editor/scene_view.js";
import { Readout } from "./editor/readout.js";
import { RefitPipeline, refitBody } from "./editor/refit.js";
import { LiveRefit } from "./editor/live_page.js";
import { LIVE } from "./editor/live_solve.js";
import { Continuing, save as saveEdit } from "./editor/save.js";
import { linkOf, Studio } from "./editor/studio.js";
import { createStore, fitted, key, liveStart, SAMPLES, snapshot, unsaved } from "./editor/state.js";

const $ = (id) => document.getElementById(id);

const store = createStore();
const state = store.state;
// Bookkeeping of the page around the state: the latest eta_i request (older
// curves are dropped), the slider's debounce, the material open (to return
// to when a switch is declined), and the cold start's prefetched curves.
const page = { etaRequest: 0, etaTimer: null, picked: null, prefetched: new Map(), liveFit: null, restTimer: 0 };

// Timings for benchmarks/editor_speed.py: when the last edit happened, and
// for each fit shown, the edit it answers and when its curve and its first
// preview frame were drawn (performance.now(), ms).
const telemetry = { lastEditAt: 0, shown: [] };
window.cfTelemetry = telemetry;

const messages = new Messages();
const say = (...args) => messages.say(...args);
const guard = (work) => messages.guard(work);

const pipeline = new RefitPipeline({
  context: () => ({ base: state.base, startFit: liveStart(state), editAt: telemetry.lastEditAt }),
  async fit(job, signal) {
    const edits = JSON.parse(job.wanted);
    const sentAt = performance.now();
    const curvesAt = { etaI: state.eta, samples: SAMPLES };
    const fit = Object.keys(edits).length
      ? await api.fitFromCurves(refitBody({ name: $("name").value, base: job.base, theta: state.theta, edits,
                                            startFit: job.startFit }), curvesAt, signal)
      : job.base;
    const fittedAt = performance.now();
    const curves = fit.curves && key(fit.curves.eta_i) === key(curvesAt.etaI)
      ? fit.curves : await api.curves(fit.id, state.eta, SAMPLES);
    return { fit, curves, sentAt, fittedAt };
  },
  show({ fit, curves, sentAt, fittedAt }, job) {
    // Recorded before present(): the preview draws the new fit at once, in it.
    const shown = { fit: fit.id, editAt: job.editAt, sentAt, fittedAt, curveAt: null, frameAt: null,
                    live: !!job.startFit, serverMs: fit.timings ? 1e3 * fit.timings.total : null };
    telemetry.shown.push(shown);
    if (telemetry.shown.length > 1000) telemetry.shown.shift();
    present(fit, curves, job.wanted);
    shown.curveAt = performance.now();
  },
  onAnswer: () => messages.clear("retry"),
  onRetry: (ms) => say(`The service is busy; retrying in ${(ms / 1000).toFixed(1)} s…`, false, "retry"),
  onReport: (error) => messages.report(error, requestRefit, "The service refused the edit: "),
  onUpdating: (on) => messages.updating(on),
  busy: (work) => messages.busy("Fitting…", work),
});

// Live refits while a point is held: solved in the page (live_page.js), the
// server's live step only for a kind the page does not solve or before the
// base's rows are in. Each starts from the last one of the drag (the fit on screen).
const live = new LiveRefit({
  worker: new Worker(new URL("./editor/live_worker.js", import.meta.url), { type: "module" }),
  rowsOf: (base, eta) => api.curves(base.id, eta, LIVE.muSamples)
    .then((c) => (base.kind === "curves" ? c.model : c.reference || c.model)),
  show({ fit, model, job }) {
    if (state.base !== job.base || !store.dispatch("liveShown", { model })) return;
    page.liveFit = fit;
    // The trace of a live refit (ms, page clock): the move's event, its edit, the message posted, the
    // worker's solve (its start and end), its answer on the page, the curve set, the frame drawn.
    const shown = { fit: fit.id, moveAt: job.moveAt, editAt: job.editAt, sentAt: job.sentAt, fittedAt: performance.now(),
                    solveStart: fit.inPage.startedAt, solveEnd: fit.inPage.endedAt, curveAt: null, frameAt: null,
                    live: "page", solveMs: fit.inPage.ms, coefficients: fit.coefficients, edits: job.edits };
    telemetry.shown.push(shown);
    if (telemetry.shown.length > 1000) telemetry.shown.shift();
    shown.curveAt = performance.now();
    previewView.hold(true);
    previewView.showFit(fit);
  },
  onError: (text) => say(`The live refit failed in the page: ${text}`),
});

function liveRefit() {
  if (!state.pointerDrag || !live.ready(state.base, state.edits)) return false;
  live.request({ base: state.base, fit: page.liveFit || state.fit, edits: JSON.parse(snapshot(state)),
                 theta: state.theta, eta: state.eta, editAt: telemetry.lastEditAt, moveAt: telemetry.lastMoveAt });
  return true;
}

// Ask for a fit of the edits on screen (await whenFitted() for it).
function requestRefit() {
  pipeline.request(snapshot(state));
}

// While a pointer rests on a point for REST_MS (a pause, not the gaps of a moving pointer), the full
// refit of the edits is asked at once: the release then finds it under way, or answered; a move after
// it aborts it (refit.js: stale).
const REST_MS = 500;
function refitAtRest() {
  clearTimeout(page.restTimer);
  page.restTimer = setTimeout(() => state.pointerDrag && pipeline.request(snapshot(state), { full: true }), REST_MS);
}

// Once no refit is pending: true when the fit on screen is the fit of the edits on screen.
const whenFitted = () => pipeline.whenIdle().then((failed) => !failed && fitted(state));

const continuing = new Continuing();

const save = () => saveEdit({
  state, name: () => $("name").value, say, report: (...args) => messages.report(...args),
  busy: (text, work) => messages.busy(text, work),
  refitFirst: () => { requestRefit(); return whenFitted(); },
  failed: () => pipeline.failed,
  async refresh(value) {
    const [materials] = await Promise.all([loadMaterials($("material"), value), studio.refresh()]);
    remember(value);
    return materials;
  },
  async onSaved(fit, edited) {
    // The saved fit goes on screen when another fit of the same edits is there (a draft refit sent
    // under the name as it was before the save's): what is shown, downloaded and compared is what was
    // saved, and the page does not call it unsaved.
    if (state.fit && state.fit.id !== fit.id && !pipeline.pending && snapshot(state) === edited) {
      const curves = await api.curves(fit.id, state.eta, SAMPLES);
      if (!pipeline.pending && snapshot(state) === edited) present(fit, curves, edited);
    }
    store.dispatch("saved", fit.id);
    readout.showSaved(state);
  },
}, continuing);

const plotView = new PlotView({
  onDrag(payload, event) {
    if (event) telemetry.lastMoveAt = event.timeStamp;
    const moved = store.dispatch("drag", payload);
    if (moved) {
      telemetry.lastEditAt = performance.now();
      if (liveRefit()) pipeline.outdate(snapshot(state));
      else requestRefit();
      refitAtRest();
    }
    return moved;
  },
  onDragEnd() {
    clearTimeout(page.restTimer);
    live.drop();
    page.liveFit = null;
    previewView.hold(false);
    store.dispatch("dragEnd");
    requestRefit();
  },
  onSelect: (point) => store.dispatch("select", point),
  onEta: setEta,
  onUndo: guard(() => history("undo")),
  onRedo: guard(() => history("redo")),
  onReset: guard(() => history("reset")),
  onSave: guard(save),
});
const previewView = new PreviewView({
  onFrame(drawn) {
    const last = telemetry.shown[telemetry.shown.length - 1];
    if (last && last.fit === drawn.fitId && last.frameAt === null) last.frameAt = performance.now();
  },
});
const exportSettings = () => ({ etaI: state.eta, roughness: Number($("roughness").value),
                                coatRoughness: Number($("coat-roughness").value) });
const sceneView = new SceneView(exportSettings);
for (const id of ["roughness", "coat-roughness"]) $(id).addEventListener("change", () => sceneView.refresh());
const readout = new Readout({ onGentler: guard(gentler), pending: () => pipeline.pending, exportSettings });
for (const id of ["roughness", "coat-roughness"]) $(id).addEventListener("input", () => readout.showDownload());
// The library, presets and typed entry, the materials an artist manages, compare mode (studio.js).
const studio = new Studio({
  store, say, guard, report: (...args) => messages.report(...args), busy: (text, work) => messages.busy(text, work),
  setBase, present, setEta, continuing, previewView, plotView, downloadFormat: () => $("format").value, exportSettings,
  edit(point) { // a typed value: as a drag released, one undo step and a refit
    if (store.dispatch("drag", point)) store.dispatch("dragEnd");
    requestRefit();
  },
  mayDiscard: () => mayDiscard(unsaved(state)),
  open: async (value, ask = true) => (!ask || mayDiscard(unsaved(state))) && openValue(value),
  picked(value) {
    page.picked = $("material").value = value;
    remember(value);
  },
  reloadPicker: (value = page.picked) => loadMaterials($("material"), value),
  sayUpload: (text, ok) => messages.sayUpload(text, ok),
});

// The colour controls (colour_view.js): a base colour and an edge tint set the curves, one undoable edit.
const colourView = new ColourView({
  async onColours({ f0, f82, seenAt }) {
    const base = state.base;
    if (!base) return null;
    const body = { f0, f82, space: "lin_rec709", seen_at: seenAt, eta_i: colourRows(base.eta_i_range, state.eta, seenAt),
                   samples: SAMPLES };
    const answer = await messages.busy("Setting the colours…", () => api.colourCurves(body));
    if (state.base !== base) return null; // another material opened meanwhile
    store.dispatch("colour", Object.fromEntries(answer.curves.map((curve) => [key(curve.eta_i), curve.rgb])));
    telemetry.lastEditAt = performance.now();
    requestRefit();
    return answer;
  },
  onFalloff: (name) => store.dispatch("falloff", name),
  async showColours(seenAt) {
    const fit = state.fit || state.base;
    if (!fit) return null;
    if (key(seenAt) === key(state.eta) && state.model) return coloursOf(state.model, state.theta);
    const curves = await api.curves(fit.id, seenAt, SAMPLES);
    return coloursOf(curves.model, curves.theta_deg);
  },
});

// The views follow the state: the plot and the saved line after every change of it.
const RENDERED = new Set(["curves", "drag", "dragEnd", "undo", "redo", "reset", "gentler", "shown", "saved",
                          "colour", "liveShown"]);
// While a pointer holds a point, the plot follows on the next animation frame
// (once a frame, with the preview's draw): the move's solve is posted first.
const plotFrame = { pending: 0 };
function renderPlot() {
  cancelAnimationFrame(plotFrame.pending);
  plotFrame.pending = 0;
  $("fit-source").textContent = state.onScreen === "page" ? "live (in page)" : "server fit";
  plotView.render(state);
  readout.showSaved(state);
}
store.subscribe((name) => {
  if (!RENDERED.has(name)) return;
  if (!(state.pointerDrag && (name === "drag" || name === "liveShown"))) renderPlot();
  else if (!plotFrame.pending) plotFrame.pending = requestAnimationFrame(renderPlot);
});

// ---------------------------------------------------------------- the fit on screen

// Everything that names a fit is set here, together: id, figures,
// coefficients, curve, download and preview.
function present(fit, curves, edits = "{}") {
  const here = key(curves.eta_i) === key(state.eta);
  readout.showFit(fit);
  store.dispatch("shown", { fit, edits, model: here ? curves.model : null });
  if (!here) showEta().catch((error) => say(error.message));
  previewView.showFit(fit);
  sceneView.showFit(fit);
}

// The model kinds this page draws: the server's registry (GET /domain).
const kindsKnown = api.domain().then((domain) => { if (!modelKindsKnown()) setModelKinds(domain); });

async function setBase(fit) {
  await kindsKnown;
  modelKind(fit); // a kind this page cannot draw is refused by name, before anything changes
  store.dispatch("openBase", fit);
  continuing.opened(fit, savedVersion(fit));
  pipeline.drop(); // answers for the previous material are dropped
  live.drop();
  page.liveFit = null;
  plotView.showBase(state);
  previewView.showBase(fit);
  $("name").value = fit.kind === "curves" ? fit.name : `${fit.name} edited`;
  $("material-source").textContent = fit.source ? fit.source.split("\n")[0].slice(0, 160) : "";
  say("");
  const early = page.prefetched.get(fit.id);
  page.prefetched.clear();
  const curves$ = early && early.eta === state.eta ? early.curves : api.curves(fit.id, state.eta, SAMPLES);
  const [curves] = await Promise.all([curves$, loadReference(fit, early && early.texture)]);
  store.dispatch("curves", { base: curves });
  present(fit, curves);
  colourView.refresh().catch((error) => say(error.message));
  live.prepare(fit, [state.eta]);
}

// The spectral reference texture of the base (its measured n, k) for the
// preview; fits without n, k show the model alone.
async function loadReference(fit, pending = null) {
  if (!previewView.ball || !fit.has_nk) return;
  try {
    previewView.setReference(await (pending || api.referenceTexture(fit.id)));
  } catch (error) {
    say(`Spectral reference unavailable: ${error.message}`);
  }
}

async function pickMaterial(value, pending = null) {
  if (!value) return;
  await messages.busy("Fitting the material…", async () => setBase(await (pending || fitOf(value))));
}

// Open a picker value (library:Au, saved:<id>) and remember it.
async function openValue(value) {
  await pickMaterial(value);
  studio.app.picked(value);
}

// ---------------------------------------------------------------- eta_i

// The curves at the current eta_i: the base's (reference, Lazanyi) and the shown fit's model.
async function showEta() {
  const request = ++page.etaRequest;
  const fit = state.fit;
  const [base, current] = await Promise.all([
    api.curves(state.base.id, state.eta, SAMPLES),
    fit.id === state.base.id ? null : api.curves(fit.id, state.eta, SAMPLES),
  ]);
  if (request !== page.etaRequest || fit !== state.fit) return; // a later eta_i (or fit) since
  store.dispatch("curves", { base, model: current ? current.model : null });
}

function setEta(eta) {
  store.dispatch("setEta", eta);
  if (state.base) live.prepare(state.base, [state.eta]);
  plotView.showEta(state);
  previewView.setEta(eta);
  colourView.setEta(eta);
  readout.showDownload();
  clearTimeout(page.etaTimer);
  page.etaTimer = setTimeout(() => {
    showEta().catch((error) => say(error.message));
    sceneView.refresh();
  }, 120);
}

// ---------------------------------------------------------------- edits

// Undo, redo or reset (each undoable), then the refit of the edits it leaves.
async function history(action) {
  if (!store.dispatch(action)) return;
  requestRefit();
  await whenFitted();
}

// "Make the edit gentler": every edit halfway back to where it started (undoable).
async function gentler() {
  if (!state.baseCurves) return;
  const from = state.base.kind === "curves" ? "model" : "reference";
  const etas = Object.keys(state.edits);
  const bases = await Promise.all(etas.map((eta) => api.curves(state.base.id, Number(eta), SAMPLES)));
  store.dispatch("gentler", Object.fromEntries(etas.map((eta, k) => [eta, bases[k][from] || bases[k].model])));
  requestRefit();
}

// ---------------------------------------------------------------- page inputs

bindPageInputs({
  unsaved: () => unsaved(state),
  picked: () => page.picked,
  onPick: guard(openValue),
  onUpload(file) {
    messages.sayUpload("");
    studio.upload(file).catch((error) => {
      if (error.status === 401) messages.report(error, () => studio.upload(file));
      else messages.sayUpload(`Not uploaded: ${error.message}`);
    });
  },
  onOpenFile(file) {
    $("open-message").textContent = "";
    studio.importFile(file).catch((error) => {
      if (error.status === 401) messages.report(error, () => studio.importFile(file));
      else $("open-message").textContent = `Not opened: ${error.message}`;
    });
  },
  onUndo: guard(() => history("undo")),
  onRedo: guard(() => history("redo")),
});

// Cold start: the material list, the first fit and the preview's shaders
// load at the same time.
guard(async () => {
  const link = linkOf(location.search); // a link opens what it names, else the material open last
  const wanted = recall() || FIRST;
  const first = link ? Promise.reject(new Error("a link")) : fitOf(wanted);
  // Its curves and reference texture are asked for as soon as it is known, while the shaders compile.
  first.then((fit) => page.prefetched.set(fit.id, prefetch(fit, state.eta, SAMPLES)), () => {});
  const picker = $("material");
  await loadMaterials(picker);
  picker.value = wanted;
  const found = picker.value === wanted;
  if (!found) picker.value = FIRST; // the remembered material is gone
  const ball = await previewView.ready;
  if (ball) ball.set({ eta: state.eta });
  page.picked = picker.value;
  await (link ? studio.openLink(link) : pickMaterial(picker.value, found ? first : null));
  document.body.dataset.ready = "true";
})();
