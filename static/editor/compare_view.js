// Compare mode's words (state.compare): what is compared with what, and the
// CIE Delta E 2000 between the two fits at the current eta_i, computed here
// from both fits' model curves (compare.js) over the plot's angles. The
// second ball is the preview's (preview_view.js), the overlaid curves the
// plot's (plot_view.js). Renders from the state; hooks:
//   onCompareBase(), onOff().

import { curvesDeltaE } from "./compare.js";
import { key } from "./state.js";

const $ = (id) => document.getElementById(id);

/** The Delta E 2000 of compare mode at the state's eta_i, or null while a curve is not in. */
export function compareFigures(state) {
  const other = state.compare;
  if (!other || !other.model || other.eta !== key(state.eta) || !state.model) return null;
  return curvesDeltaE(state.model, other.model, state.theta);
}

export class CompareView {
  constructor(hooks) {
    $("compare-base").addEventListener("click", () => hooks.onCompareBase());
    $("compare-off").addEventListener("click", () => hooks.onOff());
  }

  render(state) {
    const other = state.compare;
    $("compare-off").disabled = !other;
    $("compare-readout").hidden = !other;
    $("compare-caption").hidden = !other;
    if (!other) {
      $("compare-state").textContent = "Not comparing.";
      $("compare-de").textContent = "–";
      delete $("compare-de").dataset.fit;
      return;
    }
    const mine = state.fit ? state.fit.id.slice(0, 8) : "–";
    $("compare-caption").textContent = `Left: the fit on screen (${mine}); right: ${other.label} (${other.fit.id.slice(0, 8)}).`;
    const figures = compareFigures(state);
    if (!figures) {
      $("compare-state").textContent = `Comparing with ${other.label}…`;
      return;
    }
    $("compare-de").textContent = figures.mean.toFixed(3);
    $("compare-de").dataset.fit = other.fit.id;
    $("compare-state").textContent =
      `The fit on screen against ${other.label} at ηᵢ ${key(state.eta)}: mean ΔE₀₀ ${figures.mean.toFixed(2)}, ` +
      `max ${figures.max.toFixed(2)} at ${figures.atDeg.toFixed(0)}° (below 1 invisible side by side, above 5 clearly another colour).`;
  }
}
