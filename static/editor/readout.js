// The view of the fit on screen (state.fit): its Delta E figures (mean, and max with where it is) and label
// (figures.js reads them), id, coefficients (as its kind writes them,
// kinds.js), the pack download, the "cannot follow this edit" warning, the
// saved/unsaved line and the error heat map. Renders from the state; its
// only input is the "Make the edit gentler" button (onGentler).

import * as api from "../api.js";
import { drawErrorMap } from "../heatmap.js";
import { modelKind } from "../kinds.js";
import { formatMax, formatMean, readFigures } from "./figures.js";
import { unsaved } from "./state.js";

const $ = (id) => document.getElementById(id);

export class Readout {
  /**
   * hooks: onGentler(), pending() -> whether a refit is under way (the heat
   * map waits for a pause), exportSettings() -> the preview's {etaI, roughness, coatRoughness}.
   */
  constructor(hooks) {
    this.hooks = hooks;
    this.mapTimer = null;
    this.fit = null;
    $("reach-gentler").addEventListener("click", () => hooks.onGentler());
    $("format").addEventListener("change", () => this.showDownload());
    // The href is set again at the click: an export takes the preview's settings as they are then.
    $("download").addEventListener("click", (event) => {
      if (!this.fit) event.preventDefault();
      else this.showDownload();
    });
  }

  /**
   * The download link of the fit on screen in the chosen format, and what
   * an export will hold (hooks.exportSettings(): {etaI, roughness, coatRoughness},
   * the preview's); called again when those change.
   */
  showDownload() {
    if (!this.fit) return;
    const format = $("format").value;
    const settings = this.hooks.exportSettings();
    $("download").href = api.packURL(this.fit.id, format, settings);
    $("download-settings").textContent = api.EXPORTS.has(format)
      ? `At the preview's ηᵢ ${settings.etaI.toFixed(2)}, roughness ${settings.roughness.toFixed(2)}, ` +
        `coat roughness ${settings.coatRoughness.toFixed(2)}; the file name says all three.`
      : "Every ηᵢ of the fit: the coefficients and how to evaluate them.";
  }

  /** Everything that names the fit on screen, set together. */
  showFit(fit) {
    this.fit = fit;
    const figures = readFigures(fit);
    $("de-label").firstChild.textContent = figures.label;
    $("de-mean").textContent = formatMean(figures.mean);
    $("de-max").textContent = formatMax(figures.max);
    $("fit-id").textContent = fit.id;
    $("coefficients").textContent = modelKind(fit).describe(fit);
    const download = $("download");
    this.showDownload();
    download.setAttribute("aria-disabled", "false");
    download.setAttribute("download", "");
    this.#reach(figures.reach, figures.unfollowed);
    this.#clearErrorMap(fit);
    this.scheduleErrorMap();
  }

  // A new fit: the previous fit's map goes at once (it never stands for this one), until this one's is in.
  #clearErrorMap(fit) {
    const canvas = $("heatmap");
    if (canvas.dataset.fit === fit.id) return;
    canvas.getContext("2d").clearRect(0, 0, canvas.width, canvas.height);
    canvas.dataset.fit = "";
    $("heatmap-caption").textContent = "Measuring this fit's differences…";
  }

  // The worst miss (reach) and, in the server's words, each edited curve the fit cannot follow.
  #reach(reach, unfollowed) {
    const box = $("reach");
    $("reach-warnings").replaceChildren(
      ...unfollowed.map((text) => Object.assign(document.createElement("li"), { textContent: text })));
    if (!reach && unfollowed.length === 0) {
      box.hidden = true;
      return;
    }
    $("reach-text").textContent = reach
      ? `The model cannot follow this edit everywhere: it misses the edited curves by up to ` +
        `ΔE ${reach.max.toFixed(1)} at ${reach.thetaDeg.toFixed(0)}° and ` +
        `ηᵢ ${reach.etaI.toFixed(2)} (1 is a just-visible difference). The fit stays a valid ` +
        `reflectance (0 to 1); the curve shows what you will get.`
      : "The model cannot follow every edited curve; the curve shows what you will get.";
    box.hidden = false;
  }

  /** "Unsaved changes" while there are edits and the fit on screen is not the one saved. */
  showSaved(state) {
    const dirty = unsaved(state);
    $("save-state").textContent = dirty ? "Unsaved changes (drafts are not saved)" :
      (state.savedId && state.fit && state.savedId === state.fit.id ? "Saved" : "");
    document.body.dataset.unsaved = dirty ? "true" : "false";
  }

  /** The heat map costs a request: drawn for the fit on screen once refits pause. */
  scheduleErrorMap() {
    clearTimeout(this.mapTimer);
    this.mapTimer = setTimeout(() => {
      if (this.hooks.pending()) return this.scheduleErrorMap();
      this.#errorMap().catch(() => {});
    }, 150);
  }

  async #errorMap() {
    const fit = this.fit;
    try {
      const map = await api.errorMap(fit.id);
      if (fit !== this.fit) return;
      drawErrorMap($("heatmap"), map);
      $("heatmap").dataset.fit = fit.id;
      $("heatmap-caption").textContent = `Against the ${map.against}; dark is close, bright is a visible difference.`;
    } catch (error) {
      $("heatmap-caption").textContent = `Error map unavailable: ${error.message}`;
    }
  }
}
