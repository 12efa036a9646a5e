// The curve editor: pick a material, edit its RGB reflectance curves at one
// or more coating indices, refit on the service (POST /fits/from-curves),
// see the fit, its preview and its error map, save and download it.
//
// The page never evaluates the model itself: every curve, metric and image
// comes from the service, so the model has one definition per language.

import * as api from "./api.js";
import { drawErrorMap } from "./heatmap.js";
import { ReflectancePlot } from "./plot.js";

const SAMPLES = 46; // 0, 2, ..., 90 degrees
const HANDLES = [0, 20, 36, 50, 60, 70, 78, 84];
const FALLOFF_DEG = 9; // width of the bump a dragged point makes

const $ = (id) => document.getElementById(id);

const state = {
  base: null,       // the fit being edited (its curves are the starting point)
  fit: null,        // the current fit (the base's until the first edit)
  eta: 1.5,
  edits: {},        // eta_i (2 decimals) -> target rgb, SAMPLES x 3
  undo: [],
  redo: [],
  theta: [],
  baseCurves: null, // reference, lazanyi and base model at the current eta_i
  model: null,      // the current fit at the current eta_i
  request: 0,       // drops answers of superseded refits
  etaRequest: 0,    // drops curves of superseded eta_i (or fits)
};

const plot = new ReflectancePlot($("plot"), { onDrag: drag, onDragEnd: guard(refit) });

// ---------------------------------------------------------------- messages

function say(text, ok = false) {
  const box = $("message");
  box.textContent = text;
  box.classList.toggle("ok", ok);
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

async function pickMaterial(value) {
  if (!value) return;
  const [kind, id] = value.split(/:(.*)/s);
  await busy("Fitting the material…", async () => {
    let fit;
    if (kind === "library") {
      fit = await api.fitLibrary(id, [1.0, 2.5]);
    } else {
      const material = await api.getMaterial(id);
      fit = material.latest_fit;
    }
    await setBase(fit);
  });
}

function setBase(fit) {
  state.base = fit;
  state.fit = fit;
  state.edits = {};
  state.undo = [];
  state.redo = [];
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
  if (!fit.has_nk) $("compare").value = "none";
  $("reset").title = fit.kind === "curves" ? "Back to the saved edit as opened" : "Back to the measured data";
  say("");
  return showEta().then(showFit);
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

async function showEta() {
  $("eta-value").textContent = key(state.eta);
  const request = ++state.etaRequest;
  const [base, current] = await Promise.all([
    api.curves(state.base.id, state.eta, SAMPLES),
    state.fit.id === state.base.id ? null : api.curves(state.fit.id, state.eta, SAMPLES),
  ]);
  if (request !== state.etaRequest) return; // a later eta_i (or fit) asked since
  state.theta = base.theta_deg.map((t) => Math.round(t * 1e6) / 1e6);
  state.baseCurves = base;
  state.model = current ? current.model : base.model;
  redraw();
}

function redraw() {
  const edited = Boolean(state.edits[key(state.eta)]);
  $("plot").dataset.eta = key(state.eta);
  plot.draw({
    theta: state.theta,
    reference: state.baseCurves.reference || state.baseCurves.model,
    target: target(),
    model: state.model,
    lazanyi: $("show-lazanyi").checked ? state.baseCurves.lazanyi_adjusted : null,
    handles: HANDLES,
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
}

function snapshot() {
  return JSON.stringify(state.edits);
}

let dragStart = null;

// Move a control point; true when the target changed (then a refit follows).
function drag(channel, handle, value) {
  const k = key(state.eta);
  // The slider moved and its curves are not in yet: the plot shows another eta_i.
  if (!state.baseCurves || key(state.baseCurves.eta_i) !== k) return false;
  // Clamped: the reference can exceed 1 by rounding (1.0000000000000002 at 90 degrees).
  const current = target().map((rgb) => rgb.map((v) => Math.min(1, Math.max(0, v))));
  const i = state.theta.indexOf(HANDLES[handle]);
  const delta = value - current[i][channel];
  if (delta === 0) return false;
  if (dragStart === null) dragStart = snapshot();
  const channels = document.querySelector("input[name=channel]:checked").value === "all" ? [0, 1, 2] : [channel];
  const at = (t) => Math.exp(-0.5 * ((t - HANDLES[handle]) / FALLOFF_DEG) ** 2) * (1 - (t / 90) ** 6);
  const peak = at(HANDLES[handle]);
  for (let j = 0; j < state.theta.length; j++) {
    // Grazing (90 degrees) stays 1: the model meets 1 there whatever its coefficients.
    const w = at(state.theta[j]) / peak;
    for (const c of channels) current[j][c] = Math.min(1, Math.max(0, current[j][c] + delta * w));
  }
  state.edits[k] = current;
  redraw();
  return true;
}

async function refit() {
  if (dragStart !== null) {
    state.undo.push(dragStart);
    state.redo = [];
    dragStart = null;
  }
  await fitEdits();
}

// Refit the edits; true when the fit of the current edits is shown, false
// when the service refused (reported with `prefix`; `retry` after a 401).
async function fitEdits(prefix = "The service refused the edit: ", retry = fitEdits) {
  const etas = Object.keys(state.edits).sort();
  const request = ++state.request;
  if (!etas.length) {
    state.fit = state.base;
  } else {
    const body = {
      name: $("name").value.trim() || "edited",
      base: { fit: state.base.id },
      curves: etas.map((eta) => ({ eta_i: Number(eta), angle_deg: state.theta, rgb: state.edits[eta] })),
    };
    try {
      const fit = await busy("Fitting…", () => api.fitFromCurves(body));
      if (request !== state.request) return false;
      state.fit = fit;
      say("");
    } catch (error) {
      if (request === state.request) report(error, retry, prefix);
      redraw();
      return false;
    }
  }
  await showEta();
  await showFit();
  return request === state.request;
}

// ---------------------------------------------------------------- fit views

async function showFit() {
  const fit = state.fit;
  const edited = fit.kind === "curves";
  const model = fit.metrics.model || {};
  $("de-label").textContent = edited ? "Fit vs edited curves, mean ΔE00" : "Fit vs measured reference, mean ΔE00";
  $("de-mean").textContent = model.delta_E_mean != null ? model.delta_E_mean.toFixed(3) : "–";
  $("de-max").textContent = model.delta_E_max != null ? model.delta_E_max.toFixed(3) : "–";
  $("fit-id").textContent = fit.id;
  const rows = ["F0", "a", "alpha"].map((p) =>
    `${p.padEnd(5)} ` + fit.coefficients[p].map((row, c) => `${"RGB"[c]} [${row.map((v) => v.toFixed(5)).join(", ")}]`).join("  "));
  $("coefficients").textContent = `degree ${fit.degree}, eta_i in [${fit.eta_i_range.join(", ")}]\n${rows.join("\n")}`;
  const download = $("download");
  download.href = api.packURL(fit.id, $("format").value);
  download.setAttribute("aria-disabled", "false");
  download.setAttribute("download", "");
  await Promise.all([showPreview(), showErrorMap()]);
}

let previewURL = null;
async function showPreview() {
  const fit = state.fit;
  const compare = fit.has_nk ? $("compare").value : "none";
  const img = $("preview");
  try {
    const blob = await busy("Rendering the preview…", () => api.preview(fit.id, state.eta, compare));
    if (previewURL) URL.revokeObjectURL(previewURL);
    previewURL = URL.createObjectURL(blob);
    img.src = previewURL;
    img.dataset.fit = fit.id;
    img.alt = `Preview sphere of ${fit.name} at eta_i ${key(state.eta)}` + (compare !== "none" ? `, split with ${compare}` : "");
  } catch (error) {
    img.removeAttribute("src");
    img.alt = `Preview unavailable: ${error.message}`;
    say(`Preview unavailable: ${error.message}`);
  }
}

async function showErrorMap() {
  try {
    const map = await api.errorMap(state.fit.id);
    drawErrorMap($("heatmap"), map);
    $("heatmap-caption").textContent =
      `Against the ${map.against}: mean ${map.delta_E_mean.toFixed(3)}, max ${map.delta_E_max.toFixed(3)}.`;
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
  clearTimeout(etaTimer);
  etaTimer = setTimeout(() => {
    showEta().then(showPreview).catch((error) => say(error.message));
  }, 120);
}

async function undoRedo(from, to) {
  if (!from.length) return;
  to.push(snapshot());
  state.edits = JSON.parse(from.pop());
  redraw();
  await fitEdits();
}

async function reset() {
  state.undo.push(snapshot());
  state.redo = [];
  state.edits = {};
  await fitEdits();
}

async function save() {
  const name = $("name").value.trim();
  if (!name) {
    say("Give the material a name first.");
    $("name").focus();
    return;
  }
  // A refused refit (401, 503, 422) is reported by fitEdits: nothing was saved.
  if (!(await fitEdits("Not saved: ", save))) return;
  if (state.fit.kind !== "curves") return;
  await loadMaterials($("material").value);
  say(`Saved “${state.fit.name}”: it is in the material list (Saved) and survives restarts.`, true);
}

async function upload(file) {
  await busy("Fitting the uploaded n, k…", async () => {
    const fit = await api.uploadNK(file);
    await loadMaterials(`saved:${fit.material_id}`);
    await setBase(fit);
    say(`Fitted ${fit.name} from ${file.name}.`, true);
  });
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
$("material").addEventListener("change", guard((event) => pickMaterial(event.target.value)));
$("upload").addEventListener("change", guard((event) => event.target.files[0] && upload(event.target.files[0])));
$("eta").addEventListener("input", (event) => setEta(Number(event.target.value)));
$("show-lazanyi").addEventListener("change", redraw);
for (const radio of document.querySelectorAll("input[name=channel]")) radio.addEventListener("change", redraw);
$("undo").addEventListener("click", guard(() => undoRedo(state.undo, state.redo)));
$("redo").addEventListener("click", guard(() => undoRedo(state.redo, state.undo)));
$("reset").addEventListener("click", guard(reset));
$("save").addEventListener("click", guard(save));
$("compare").addEventListener("change", guard(showPreview));
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

guard(async () => {
  await loadMaterials();
  const picker = $("material");
  picker.value = "library:Au";
  await pickMaterial(picker.value);
  document.body.dataset.ready = "true";
})();
