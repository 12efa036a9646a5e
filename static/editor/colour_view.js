// The colour controls: a base colour (F0) and an edge tint (F82 tint), each a
// colour picker with its sRGB hex, read as seen in air or under the coat at
// the current eta_i (a toggle), a warmth-at-grazing knob on the edge tint,
// and the falloff of a dragged point. Applying them asks the service for the
// metal's curves (POST /colour-curves: the inversion POST /fits uses for f0
// and f82) and hands them to the editor as one undoable edit, refitted as
// any edit; the curve handles stay for fine control.
// Hooks: onColours({f0, f82, seenAt}) -> Promise of {reachable, F82_error}
// (linear Rec.709 colours), onFalloff(name), showColours(seenAt) -> Promise
// of {f0, f82} (linear Rec.709) of the fit on screen seen there.

import { hexToLinear, linearToHex, warmer } from "./colour.js";

const $ = (id) => document.getElementById(id);
const CHANNELS = ["red", "green", "blue"];

export class ColourView {
  constructor(hooks) {
    this.hooks = hooks;
    this.eta = 1.5;
    for (const [picker, hex] of [["base-colour", "base-hex"], ["edge-colour", "edge-hex"]]) {
      // A picker applies when it closes (change), its hex field as it is typed; each shows the other.
      $(picker).addEventListener("input", () => { $(hex).value = $(picker).value; });
      $(picker).addEventListener("change", () => this.apply());
      $(hex).addEventListener("change", () => {
        const typed = this.#hex(hex);
        if (typed === null) return;
        $(picker).value = linearToHex(typed);
        this.apply();
      });
    }
    $("warmth").addEventListener("input", () => this.#showWarmth());
    $("warmth").addEventListener("change", () => this.apply());
    for (const radio of document.querySelectorAll("input[name=colour-at]")) {
      radio.addEventListener("change", () => this.refresh());
    }
    $("falloff").addEventListener("change", () => hooks.onFalloff($("falloff").value));
    this.#showWarmth();
  }

  // The linear Rec.709 colour typed in field `id`, or null (the rule said, the field marked).
  #hex(id) {
    try {
      const rgb = hexToLinear($(id).value);
      $(id).setAttribute("aria-invalid", "false");
      return rgb;
    } catch (error) {
      $(id).setAttribute("aria-invalid", "true");
      this.#say(error.message, true);
      return null;
    }
  }

  #say(text, error = false) {
    $("colour-message").textContent = text;
    $("colour-message").classList.toggle("error", error);
  }

  // Where the colours are seen: 1 in air, else the coat's eta_i.
  seenAt() {
    const at = document.querySelector("input[name=colour-at]:checked");
    return at && at.value === "coat" ? this.eta : 1;
  }

  /** The edge tint the knob makes of the picked one (linear Rec.709). */
  edgeTint() {
    return warmer(hexToLinear($("edge-colour").value), Number($("warmth").value));
  }

  #showWarmth() {
    const w = Number($("warmth").value);
    $("warmth-value").value = `${w > 0 ? "+" : ""}${w.toFixed(2)}`;
    $("warmth-tint").textContent = linearToHex(this.edgeTint());
    $("warmth-tint").style.setProperty("--tint", linearToHex(this.edgeTint()));
  }

  /** The coat's eta_i (what "under the coat" reads the colours at). */
  setEta(eta) {
    this.eta = eta;
    $("colour-at-eta").textContent = eta.toFixed(2);
  }

  /** The pickers show the colours of the fit on screen as the toggle reads them (the knob back at 0). */
  async refresh() {
    const shown = await this.hooks.showColours(this.seenAt());
    if (!shown) return;
    $("base-colour").value = $("base-hex").value = linearToHex(shown.f0);
    $("edge-colour").value = $("edge-hex").value = linearToHex(shown.f82);
    $("warmth").value = "0";
    this.#showWarmth();
    this.#say("");
  }

  /** Set the curves to the metal of the picked colours (the service's inversion); one undoable edit. */
  async apply() {
    const f0 = this.#hex("base-hex"), picked = this.#hex("edge-hex");
    if (f0 === null || picked === null) return;
    this.#showWarmth();
    const seenAt = this.seenAt();
    const where = seenAt === 1 ? "in air" : `under a coat of ${seenAt.toFixed(2)}`;
    try {
      const answer = await this.hooks.onColours({ f0, f82: this.edgeTint(), seenAt });
      if (!answer) return;
      const missed = answer.reachable.map((ok, c) => (ok ? null : `${CHANNELS[c]} by ${Math.abs(answer.F82_error[c]).toFixed(3)}`))
        .filter(Boolean);
      this.#say(missed.length
        ? `No metal reaches this edge tint ${where} in ${missed.join(", ")} (ACEScg): the nearest is taken.`
        : `Curves set to the metal of these colours ${where}; the fit follows.`, missed.length > 0);
    } catch (error) {
      this.#say(`Colours not applied: ${error.message}`, true);
    }
  }
}
