// The view of the preview: the WebGL2 shader ball (preview.js) of the fit
// on screen, its bands (Split: model | Lazanyi | reference; the reference
// bands only for a base with measured n, k), environment, exposure,
// roughness and clear coat. It draws whatever kind the fit is (kinds.js).
// `ready` resolves with the ShaderBall, or null when WebGL2 is missing (the
// page says why and works without a preview).

import { ENVIRONMENT, PANEL, ShaderBall } from "../preview.js";

const $ = (id) => document.getElementById(id);

const SPLITS = {
  all: [PANEL.model, PANEL.lazanyi, PANEL.reference],
  reference: [PANEL.model, PANEL.reference],
  lazanyi: [PANEL.model, PANEL.lazanyi],
  none: [PANEL.model],
};

export class PreviewView {
  /** hooks: onFrame(drawn state) after every frame drawn. */
  constructor(hooks = {}) {
    this.ball = null;
    this.hasReference = false;
    this.ready = ShaderBall.create($("preview"), $("preview-labels"), $("preview-lighting")).then((ball) => {
      this.ball = ball;
      window.cfPreview = ball; // for the parity tests and benchmarks
      ball.onFrame = (drawn) => {
        if (hooks.onFrame) hooks.onFrame(drawn);
        const other = this.otherBall;
        if (other && String(other.state.orbit) !== String(drawn.orbit)) this.#follow();
      };
      this.settings();
      return ball;
    }).catch((error) => {
      const box = $("preview-error");
      box.hidden = false;
      box.textContent = `The real-time preview is unavailable: ${error.message}`;
      return null;
    });
    for (const id of ["compare", "environment", "exposure", "roughness", "coat", "coat-roughness"]) {
      $(id).addEventListener("input", () => this.settings());
    }
  }

  /** The settings of the controls, on the ball. */
  settings() {
    $("exposure-value").textContent = Number($("exposure").value).toFixed(1);
    $("roughness-value").textContent = Number($("roughness").value).toFixed(2);
    $("coat-roughness-value").textContent = Number($("coat-roughness").value).toFixed(2);
    $("coat-roughness").disabled = !$("coat").checked;
    $("coat-why").hidden = $("coat").checked; // with no coat, why eta_i still matters
    if (!this.ball) return;
    this.ball.set({
      environment: ENVIRONMENT[$("environment").value], exposure: Number($("exposure").value),
      roughness: Number($("roughness").value), coated: $("coat").checked,
      coatRoughness: Number($("coat-roughness").value),
    });
    this.#panels();
    this.#follow();
  }

  #panels() {
    // While comparing, each ball shows its model alone (the Split menu waits).
    $("compare").disabled = !this.hasReference || Boolean(this.comparing);
    if (!this.ball) return;
    this.ball.set({ panels: SPLITS[this.hasReference && !this.comparing ? $("compare").value : "none"],
                    caption: this.comparing ? "The fit on screen" : "" });
  }

  /** A new base: whether it has a spectral reference (measured n, k) to compare with. */
  showBase(base) {
    this.hasReference = Boolean(base.has_nk);
    this.#panels();
  }

  /** The base's reference texture (api.referenceTexture), once in. */
  setReference(texture) {
    if (this.ball) this.ball.setReference(texture);
    this.#panels();
  }

  setEta(eta) {
    if (this.ball) this.ball.set({ eta });
    this.#follow();
  }

  /** Whether a handle is held: the ball draws at half resolution meanwhile. */
  hold(on) {
    if (this.ball && Boolean(this.ball.state.held) !== on) this.ball.set({ held: on });
  }

  /** The fit on screen, drawn at once. */
  showFit(fit) {
    if (this.ball) this.ball.setFit(fit);
  }

  /**
   * Compare mode: `fit` drawn by a second ball beside the first (same
   * settings, eta_i and orbit; the model alone on both), or null to end it.
   * The second ball is made on first use.
   */
  async compare(fit, label = "") {
    this.comparing = fit;
    this.comparedLabel = label;
    $("compare-box").hidden = !fit;
    this.#panels();
    if (!fit || !this.ball) return;
    if (!this.other) {
      this.other = ShaderBall.create($("preview-compare"), $("preview-compare-labels"));
      window.cfPreviewCompare = this.other; // for the tests
    }
    const other = await this.other;
    this.otherBall = other;
    if (this.comparing !== fit) return;
    other.setFit(fit);
    this.#follow();
  }

  // The second ball takes the first one's settings (the orbit too) when comparing.
  #follow() {
    if (!this.comparing || !this.other) return;
    this.other.then((other) => {
      const s = this.ball.state;
      other.set({ eta: s.eta, environment: s.environment, exposure: s.exposure, roughness: s.roughness,
                  coated: s.coated, coatRoughness: s.coatRoughness, orbit: s.orbit, panels: [PANEL.model],
                  caption: `Compared: ${this.comparedLabel || "another fit"}` });
    });
  }
}
