// Colours of the editor's colour controls (a base colour and an edge tint):
// sRGB hex <-> linear Rec.709 <-> linear ACEScg, as colour-science computes
// them (tests/static/test_editor_colour.py compares them), the warmth knob,
// the colours read back from a curve, and the coating indices a colour edit
// sets. No DOM, no fetch: node --test runs it (tests/static/js/colour.test.mjs).

import { key } from "./state.js";

// Linear Rec.709 (D65) <-> linear ACEScg (ACES white), CAT02 adapted (white to
// white): colour.RGB_to_RGB(..., "ITU-R BT.709", "ACEScg", chromatic_adaptation_transform="CAT02"),
// the matrices of fitting/exports/colour_space.py, printed to 17 digits.
export const REC709_TO_ACESCG = [
  [0.6130828922201954, 0.34116705424414645, 0.0457500535356585],
  [0.07000354980712019, 0.9180628304078239, 0.01193361978505548],
  [0.02049077783814031, 0.10676398759098073, 0.8727452345708786],
];
export const ACESCG_TO_REC709 = [
  [1.705079643607503, -0.6242334614728385, -0.08084618213466577],
  [-0.12970053011660546, 1.1384685465691107, -0.00876801645250467],
  [-0.02416634494252406, -0.12461415805258193, 1.1487805029951064],
];
// Rec.709 luminance weights (ITU-R BT.709): the warmth knob keeps the tint's luminance.
const LUMA = [0.2126, 0.7152, 0.0722];
export const F82_COS = 1 / 7; // cos 82 degrees as Hoffman's F82 model takes it
export const ROW_STEP = 0.5; // a colour edit sets the curves every ROW_STEP of eta_i over the domain

const HEX = /^#?([0-9a-f]{6})$/i;
const clamp01 = (v) => Math.min(1, Math.max(0, v));
const apply = (M, v) => M.map((row) => row[0] * v[0] + row[1] * v[1] + row[2] * v[2]);

/** The sRGB transfer function decoded (IEC 61966-2-1; colour-science's eotf_sRGB). */
export const srgbDecode = (v) => (v <= 0.04045 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4);

/** The sRGB transfer function encoded (colour-science's eotf_inverse_sRGB). */
export const srgbEncode = (v) => (v <= 0.0031308 ? 12.92 * v : 1.055 * v ** (1 / 2.4) - 0.055);

/** `#rrggbb` (the `#` optional, any case) to linear Rec.709 in [0, 1]; an Error naming the rule otherwise. */
export function hexToLinear(hex) {
  const found = HEX.exec(String(hex).trim());
  if (!found) throw new Error(`A colour must be sRGB hex #rrggbb, got ${JSON.stringify(String(hex))}`);
  const digits = found[1];
  return [0, 2, 4].map((i) => srgbDecode(parseInt(digits.slice(i, i + 2), 16) / 255));
}

/** Linear Rec.709 (clipped to [0, 1]) to `#rrggbb`, lower case. */
export function linearToHex(rgb) {
  return "#" + rgb.map((v) => Math.round(255 * srgbEncode(clamp01(v))).toString(16).padStart(2, "0")).join("");
}

export const rec709ToACEScg = (rgb) => apply(REC709_TO_ACESCG, rgb);
export const ACEScgToRec709 = (rgb) => apply(ACESCG_TO_REC709, rgb);

/**
 * The warmth knob: the edge tint (linear Rec.709) made warmer (`warmth` > 0:
 * red up, blue down) or cooler (< 0), in [-1, 1]: gains 2^(warmth / 2) on
 * red and 2^(-warmth / 2) on blue, then the whole scaled back to the tint's
 * luminance, each channel clipped to [0, 1]. 0 leaves it as it is.
 */
export function warmer(tint, warmth) {
  const w = Math.min(1, Math.max(-1, Number(warmth) || 0));
  if (w === 0) return tint.map(clamp01);
  const shifted = [tint[0] * 2 ** (w / 2), tint[1], tint[2] * 2 ** (-w / 2)];
  const y0 = LUMA[0] * tint[0] + LUMA[1] * tint[1] + LUMA[2] * tint[2];
  const y1 = LUMA[0] * shifted[0] + LUMA[1] * shifted[1] + LUMA[2] * shifted[2];
  const scale = y1 > 0 ? y0 / y1 : 1;
  return shifted.map((v) => clamp01(v * scale));
}

const schlick82 = (F0) => F0 + (1 - F0) * (1 - F82_COS) ** 5;

/**
 * The base colour (F0) and edge tint (F82 tint) of a curve (rows of linear
 * ACEScg at the angles `theta`, degrees, from 0 up past 82), in linear
 * Rec.709: F0 the row at 0 degrees; the reflectance at cos theta 1/7
 * (linear in angle between the rows around it) taken to Rec.709 as a
 * colour, divided by Schlick's of the Rec.709 F0 there (as the service
 * reads the tint, service/jobs/edge_tint.py). Each clipped to [0, 1].
 */
export function coloursOf(curve, theta) {
  const at = (Math.acos(F82_COS) * 180) / Math.PI;
  let j = 0;
  while (j < theta.length - 2 && theta[j + 1] < at) j++;
  const f = (at - theta[j]) / (theta[j + 1] - theta[j]);
  const r82 = [0, 1, 2].map((c) => curve[j][c] + f * (curve[j + 1][c] - curve[j][c]));
  const f0 = ACEScgToRec709(curve[0]).map(clamp01);
  const edge = ACEScgToRec709(r82).map((v, c) => clamp01(clamp01(v) / schlick82(f0[c])));
  return { f0, f82: edge };
}

/**
 * The coating indices a colour edit sets the curves at, sorted: every
 * ROW_STEP of the domain [lo, hi] from lo (and hi), the current `eta` and
 * `seenAt` (where the colours are seen), each once (by key()).
 */
export function colourRows([lo, hi], eta, seenAt) {
  const rows = new Map();
  const add = (v) => { if (v >= lo - 1e-9 && v <= hi + 1e-9) rows.set(key(v), Number(key(v))); };
  for (let v = lo; v < hi + 1e-9; v += ROW_STEP) add(v);
  [hi, eta, seenAt].forEach(add);
  return [...rows.values()].sort((a, b) => a - b);
}
