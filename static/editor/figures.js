// The one place the editor reads a fit's error figures (FitPublic.metrics):
// the Delta E figure on screen, its label, and the worst miss behind the
// "cannot follow this edit" warning. When the metrics' JSON changes shape,
// this module is what changes (the views only show what it returns).
//
// The shape (service/schemas/fits.py FitMetrics, fitting.fits.metrics
// ErrorMetrics.figure): `metrics.figure` is the fit's one figure, the same
// the pack JSON and the GLSL / HLSL headers quote: {against (in words),
// delta_E_mean, delta_E_max, max_at: {eta_i, theta_deg} or null}. For a
// curve fit with a base it is the fit against the whole blended edited
// target; for an n, k or library fit, against the measured metal.

// An edit is beyond what the model can follow when the fit misses the
// blended target by more than this (Delta E 2000) somewhere.
export const REACH_DE = 3.0;

/**
 * The figures of `fit` to show: {label, mean (a number or null), max: null
 * or {value, thetaDeg, etaI} (thetaDeg and etaI null when the fit does not
 * say where), reach: null or {max, thetaDeg, etaI} (reach only for a curve
 * fit that misses its target by more than REACH_DE somewhere), unfollowed:
 * the server's words for each edited curve the fit cannot follow
 * (`metrics.details.warnings` of a curve fit: where and by how much), else []}.
 */
export function readFigures(fit) {
  const figure = (fit.metrics && fit.metrics.figure) || {};
  const mean = Number.isFinite(figure.delta_E_mean) ? figure.delta_E_mean : null;
  const at = figure.max_at || null;
  const max = Number.isFinite(figure.delta_E_max)
    ? { value: figure.delta_E_max, thetaDeg: at ? at.theta_deg : null, etaI: at ? at.eta_i : null }
    : null;
  const reach = fit.kind === "curves" && at && figure.delta_E_max > REACH_DE
    ? { max: figure.delta_E_max, thetaDeg: at.theta_deg, etaI: at.eta_i }
    : null;
  const details = (fit.metrics && fit.metrics.details) || {};
  const unfollowed = fit.kind === "curves" && Array.isArray(details.warnings)
    ? details.warnings.filter((w) => typeof w === "string")
    : [];
  return {
    label: figure.against ? `Against ${figure.against}, mean ΔE` : "Mean ΔE",
    mean,
    max,
    reach,
    unfollowed,
  };
}

/** The figure as the readout writes it. */
export const formatMean = (mean) => (mean === null ? "–" : mean.toFixed(3));

/** The worst point as the readout writes it: its Delta E and where (the angle inside the coating, eta_i). */
export const formatMax = (max) => {
  if (max === null) return "–";
  const where = max.thetaDeg === null ? "" : ` at ${max.thetaDeg.toFixed(0)}°, ηᵢ ${max.etaI.toFixed(2)}`;
  return `${max.value.toFixed(3)}${where}`;
};
