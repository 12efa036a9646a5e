// The view of the curves: the reflectance plot (plot.js) of the base's
// reference, the edited target, the fit on screen and adjusted Lazanyi at
// the current eta_i; the eta_i slider and the chips of the edited eta_i;
// the channel to drag; Undo, Redo, Reset and Save's enabled states.
// Renders from the state (render(state)); its inputs call `hooks`:
//   onDrag({channel, handle, value, pointer, all}, pointer event or null) -> whether the point moved,
//   onDragEnd(), onSelect({channel, handle}), onEta(eta), onUndo(), onRedo(), onReset(), onSave().
// In compare mode the other fit's curve at eta_i is drawn too (state.compare).
// The plot's data-eta is the slider's eta_i; data-curves-eta the eta_i of the
// curves drawn, which follow it once they are in (a moved slider asks for them).

import { ReflectancePlot } from "../plot.js";
import { HANDLES, key, target } from "./state.js";

const $ = (id) => document.getElementById(id);

const channel = () => document.querySelector("input[name=channel]:checked").value;

export class PlotView {
  constructor(hooks) {
    this.hooks = hooks;
    this.state = null;
    this.plot = new ReflectancePlot($("plot"), {
      onDrag: (c, handle, value, pointer = false, event = null) =>
        hooks.onDrag({ channel: c, handle, value, pointer, all: channel() === "all" }, event),
      onDragEnd: () => hooks.onDragEnd(),
      onSelect: (c, handle) => hooks.onSelect({ channel: c, handle }),
    });
    $("eta").addEventListener("input", (event) => hooks.onEta(Number(event.target.value)));
    const again = () => this.state && this.render(this.state);
    $("show-lazanyi").addEventListener("change", again);
    for (const radio of document.querySelectorAll("input[name=channel]")) radio.addEventListener("change", again);
    $("undo").addEventListener("click", () => hooks.onUndo());
    $("redo").addEventListener("click", () => hooks.onRedo());
    $("reset").addEventListener("click", () => hooks.onReset());
    $("save").addEventListener("click", () => hooks.onSave());
  }

  /** The slider's domain and the labels that depend on the base (a new material opened). */
  showBase(state) {
    const fit = state.base;
    const [lo, hi] = fit.eta_i_range;
    const slider = $("eta");
    slider.min = lo;
    slider.max = hi;
    slider.disabled = hi <= lo;
    slider.value = state.eta;
    $("reset").title = fit.kind === "curves" ? "Back to the saved edit as opened" : "Back to the measured data";
  }

  /** The slider's value and label. */
  showEta(state) {
    $("eta").value = state.eta;
    $("eta-value").textContent = key(state.eta);
  }

  render(state) {
    this.state = state;
    if (!state.baseCurves) return;
    $("plot").dataset.eta = key(state.eta);
    $("plot").dataset.curvesEta = key(state.baseCurves.eta_i);
    $("eta-value").textContent = key(state.eta);
    this.plot.draw({
      theta: state.theta,
      reference: state.baseCurves.reference || state.baseCurves.model,
      target: target(state),
      model: state.model,
      lazanyi: $("show-lazanyi").checked ? state.baseCurves.lazanyi_adjusted : null,
      compare: state.compare && state.compare.eta === key(state.eta) ? state.compare.model : null,
      handles: HANDLES,
      criticalDeg: state.eta > 1 ? (Math.asin(1 / state.eta) * 180) / Math.PI : null,
      channel: channel(),
      edited: Boolean(state.edits[key(state.eta)]),
    });
    const etas = Object.keys(state.edits).sort();
    this.#chips(etas);
    $("undo").disabled = !state.undo.length;
    $("redo").disabled = !state.redo.length;
    $("reset").disabled = !etas.length;
    $("save").disabled = !etas.length;
  }

  // The chips of the edited eta_i, made again only when the list changes (not on every move of a drag).
  #chips(etas) {
    const list = $("edited-etas");
    if (list.dataset.etas === etas.join(" ") && list.childNodes.length) return;
    list.dataset.etas = etas.join(" ");
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
        button.addEventListener("click", () => this.hooks.onEta(Number(eta)));
        list.append(button, " ");
      }
    }
  }
}
