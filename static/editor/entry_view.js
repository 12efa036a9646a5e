// Typed entry: the coating index eta_i as a number (beside the slider), the
// coat presets (GET /coat-presets: air, water, lacquer, glass, ...: a button
// each, its source as its title, the one at eta_i pressed) and the selected control point's value.
// Each input is checked before anything changes (a refusal names the rule
// and the value, and changes nothing); a valid one calls the same hooks as
// the slider and a drag, so a typed value refits as a drag does.
// Renders from the state (render(state)); hooks:
//   onEta(eta), onPoint({channel, handle, value}).

import { HANDLES, key, target } from "./state.js";

const $ = (id) => document.getElementById(id);
const CHANNELS = ["red", "green", "blue"];

/**
 * The number typed for `name`, or why not: {value} or {error}; it must be
 * a finite number within [lo, hi].
 */
export function parseTyped(text, lo, hi, name) {
  const trimmed = String(text).trim();
  const value = trimmed === "" ? NaN : Number(trimmed);
  if (!Number.isFinite(value)) return { error: `${name} must be a number, got “${trimmed}”.` };
  if (value < lo || value > hi) return { error: `${name} must lie in [${lo}, ${hi}], got ${trimmed}.` };
  return { value };
}

export class EntryView {
  constructor(hooks) {
    this.hooks = hooks;
    this.state = null;
    this.presetsShown = null;
    this.chosen = null; // the preset last pressed
    $("eta-typed").addEventListener("change", () => this.#eta($("eta-typed").value));
    $("point-value").addEventListener("change", () => this.#point($("point-value").value));
  }

  #say(text, error = false) {
    $("entry-message").textContent = text;
    $("entry-message").classList.toggle("error", error);
  }

  #domain() {
    const [lo, hi] = this.state && this.state.base ? this.state.base.eta_i_range : [1, 2.5];
    return [Number(lo.toFixed(2)), Number(hi.toFixed(2))];
  }

  #eta(text, preset = null) {
    const [lo, hi] = this.#domain();
    const typed = parseTyped(text, lo, hi, "ηᵢ (the material's domain)");
    $("eta-typed").setAttribute("aria-invalid", typed.error ? "true" : "false");
    if (typed.error) {
      this.#say(typed.error, true);
      if (this.state) this.render(this.state);
      return;
    }
    this.#say(preset ? `Coat: ${preset}.` : "");
    this.hooks.onEta(typed.value);
  }

  #point(text) {
    const selected = this.state && this.state.selected;
    if (!selected) return;
    const typed = parseTyped(text, 0, 1, "A reflectance");
    $("point-value").setAttribute("aria-invalid", typed.error ? "true" : "false");
    if (typed.error) {
      this.#say(typed.error, true);
      return;
    }
    this.#say("");
    this.hooks.onPoint({ ...selected, value: typed.value });
  }

  render(state) {
    this.state = state;
    const [lo, hi] = this.#domain();
    const eta = $("eta-typed");
    Object.assign(eta, { min: lo, max: hi });
    if (document.activeElement !== eta) eta.value = key(state.eta);
    if (this.presetsShown !== state.presets || this.presetsDomain !== `${lo}-${hi}`) this.#presets(state.presets, lo, hi);
    // The preset chosen stays pressed while eta_i is its index (two presets may share one); else the first at eta_i.
    const at = (p) => key(p.eta_i) === key(state.eta);
    const chosen = state.presets.find((p) => p.id === this.chosen);
    const match = chosen && at(chosen) ? chosen : state.presets.find(at);
    for (const button of $("coat-presets").children) {
      button.setAttribute("aria-pressed", String(Boolean(match) && button.dataset.id === match.id));
    }
    const point = $("point-value");
    const selected = state.selected;
    const curve = target(state);
    point.disabled = !selected || !curve;
    if (!selected || !curve) return;
    const angle = HANDLES[selected.handle];
    $("point-name").textContent = `${CHANNELS[selected.channel]} at ${angle}°`;
    if (document.activeElement !== point) point.value = curve[state.theta.indexOf(angle)][selected.channel].toFixed(3);
  }

  #presets(presets, lo, hi) {
    this.presetsShown = presets;
    this.presetsDomain = `${lo}-${hi}`;
    $("coat-presets").replaceChildren(...presets.map((preset) => {
      const button = document.createElement("button");
      button.type = "button";
      button.dataset.id = preset.id;
      button.textContent = `${preset.name} ${Number.isInteger(preset.eta_i) ? preset.eta_i.toFixed(1) : preset.eta_i}`;
      button.title = preset.source;
      // A coat outside the material's fitted domain cannot be previewed with this fit.
      button.disabled = preset.eta_i < lo - 1e-9 || preset.eta_i > hi + 1e-9;
      button.addEventListener("click", () => {
        this.chosen = preset.id;
        this.#eta(String(preset.eta_i), preset.name);
      });
      return button;
    }));
  }
}
