// The one place the editor reads a fit's error figures (FitPublic.metrics):
// the Delta E figure on screen, its label, and the worst miss behind the
// "cannot follow this edit" warning. When the metrics' JSON changes shape,
// this module is what changes (the views only show what it returns).
//
// Today's shape (service/schemas/fits.py FitMetrics): `metrics.model` is
// the float16 fit against what it was fitted to at its samples;
// `metrics.details.target` (curve fits) the fit against the whole blended
// edited target on 46 angles x 31 eta_i, with `delta_E_max`, `at_theta_deg`
// and `at_eta_i` of the max. The editor shows the latter where there is one.

// An edit is beyond what the model can follow when the fit misses the
// blended target by more than this (Delta E 2000) somewhere.
export const REACH_DE = 3.0;

/**
 * The figures of `fit` to show: {label, mean (a number or null), reach:
 * null or {max, thetaDeg, etaI}} (reach only for a curve fit that misses its
 * target by more than REACH_DE somewhere).
 */
export function readFigures(fit) {
  const metrics = fit.metrics || {};
  const edited = fit.kind === "curves";
  const target = (metrics.details && metrics.details.target) || null;
  const shown = target || metrics.model || {};
  const mean = Number.isFinite(shown.delta_E_mean) ? shown.delta_E_mean : null;
  const reach = edited && target && target.delta_E_max > REACH_DE
    ? { max: target.delta_E_max, thetaDeg: target.at_theta_deg, etaI: target.at_eta_i }
    : null;
  return {
    label: edited ? "Fit vs edited curves, mean ΔE" : "Fit vs measured reference, mean ΔE",
    mean,
    reach,
  };
}

/** The figure as the readout writes it. */
export const formatMean = (mean) => (mean === null ? "–" : mean.toFixed(3));
