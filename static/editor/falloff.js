// How far a dragged control point reaches along its curve (the falloff
// control): "none" moves the point alone (its neighbouring handles stay
// where they are), "narrow" and "wide" move its neighbours too, by a
// Gaussian of FALLOFFS[name] degrees. No DOM: node --test runs it
// (tests/static/js/state.test.mjs).

export const FALLOFFS = { none: 0, narrow: 9, wide: 20 }; // Gaussian widths, degrees (none: the point alone)
export const DEFAULT_FALLOFF = "none";

const smooth = (x) => (x <= 0 ? 0 : x >= 1 ? 1 : x * x * (3 - 2 * x));

/**
 * The weight (1 at the point) with which a drag of the handle at
 * `handleDeg` moves the curve at `t` degrees. "none": 1 at the handle,
 * falling smoothly (smoothstep) to 0 at the neighbouring handles of
 * `handles` (sorted angles; 90 degrees past the last), so every other
 * handle keeps its value. A Gaussian otherwise. Always 0 at 90 degrees,
 * where the model is 1 whatever its coefficients.
 */
export function falloffWeight(t, handleDeg, falloff, handles) {
  const width = FALLOFFS[falloff];
  if (width === undefined) throw new Error(`falloff must be one of ${Object.keys(FALLOFFS).join(", ")}, got ${JSON.stringify(falloff)}`);
  if (width === 0) {
    const i = handles.indexOf(handleDeg);
    const left = i > 0 ? handles[i - 1] : null;
    const right = i < handles.length - 1 ? handles[i + 1] : 90;
    if (t === handleDeg) return 1;
    if (t < handleDeg) return left === null ? 1 : smooth((t - left) / (handleDeg - left));
    return right > handleDeg ? smooth((right - t) / (right - handleDeg)) : 0;
  }
  const at = (x) => Math.exp(-0.5 * ((x - handleDeg) / width) ** 2) * (1 - (x / 90) ** 6);
  return at(t) / at(handleDeg);
}
