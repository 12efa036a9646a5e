// Compare mode's arithmetic: the CIE Delta E 2000 between two fits' curves,
// computed in the browser from the curves the editor already has (GET
// /fits/{id}/curves: linear ACEScg reflectance against the angle). Pure:
// node --test runs it (tests/static/js/compare.test.mjs), and
// tests/static/test_editor_compare_de.py checks it against the Python the
// fits are scored with (fitting.colour.delta_e.delta_E_map).
//
//   ACEScg_to_Lab(rgb): linear ACEScg (AP1 primaries, ACES white) to CIE
//     1976 L*a*b* with the ACES white as reference white, L in [0, 100];
//     as fitting.colour.colorimetry.ACEScg_to_Lab (the linear segment of
//     the CIE formula below (6/29)^3, so negative input is defined).
//   delta_E_2000(Lab1, Lab2): CIEDE2000 (Sharma, Wu and Dalal 2005,
//     Eq. 1-22; kL = kC = kH = 1).
//   curvesDeltaE(a, b, theta): mean and max over the angles of two curves
//     (n x 3, linear ACEScg) and the angle of the max.

// ACEScg to CIE XYZ (colour-science's RGB_COLOURSPACES["ACEScg"].matrix_RGB_to_XYZ).
const M = [
  [0.6624541811085055, 0.13400420645643313, 0.15618768700490773],
  [0.2722287167809146, 0.6740817658111483, 0.05368951740793703],
  [-0.005574649490394109, 0.004060733528982825, 1.010339100312997],
];
// The reference white: XYZ of ACEScg (1, 1, 1).
const XYZ_N = M.map((row) => row[0] + row[1] + row[2]);
const DELTA = 6 / 29;

const fLab = (t) => (t > DELTA ** 3 ? Math.cbrt(t) : t / (3 * DELTA * DELTA) + 4 / 29);

/** Linear ACEScg [r, g, b] to CIE L*a*b* (ACES white), [L, a, b]. */
export function ACEScg_to_Lab(rgb) {
  const f = M.map((row, i) => fLab((row[0] * rgb[0] + row[1] * rgb[1] + row[2] * rgb[2]) / XYZ_N[i]));
  return [116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])];
}

const RAD = Math.PI / 180;
const hueDeg = (b, a) => {
  // Achromatic: hue 0, as colour-science sets it.
  if (a === 0 && b === 0) return 0;
  const h = Math.atan2(b, a) / RAD;
  return h < 0 ? h + 360 : h;
};

/** CIEDE2000 between two L*a*b* colours (Sharma et al. 2005). */
export function delta_E_2000([L1, a1, b1], [L2, a2, b2]) {
  const Cbar = (Math.hypot(a1, b1) + Math.hypot(a2, b2)) / 2;
  const C7 = Cbar ** 7;
  const G = 0.5 * (1 - Math.sqrt(C7 / (C7 + 25 ** 7)));
  const ap1 = (1 + G) * a1, ap2 = (1 + G) * a2;
  const Cp1 = Math.hypot(ap1, b1), Cp2 = Math.hypot(ap2, b2);
  const hp1 = hueDeg(b1, ap1), hp2 = hueDeg(b2, ap2);
  const dL = L2 - L1, dC = Cp2 - Cp1;
  // The hue difference: 0 when either colour is achromatic; else the short way round.
  let dh = 0;
  if (Cp1 * Cp2 !== 0) {
    dh = hp2 - hp1;
    if (dh > 180) dh -= 360;
    else if (dh < -180) dh += 360;
  }
  const dH = 2 * Math.sqrt(Cp1 * Cp2) * Math.sin((dh / 2) * RAD);
  const Lbar = (L1 + L2) / 2, Cpbar = (Cp1 + Cp2) / 2;
  let hbar = hp1 + hp2;
  if (Cp1 * Cp2 !== 0) {
    if (Math.abs(hp1 - hp2) <= 180) hbar /= 2;
    else hbar = hbar < 360 ? (hbar + 360) / 2 : (hbar - 360) / 2;
  }
  const T = 1 - 0.17 * Math.cos((hbar - 30) * RAD) + 0.24 * Math.cos(2 * hbar * RAD)
    + 0.32 * Math.cos((3 * hbar + 6) * RAD) - 0.2 * Math.cos((4 * hbar - 63) * RAD);
  const SL = 1 + (0.015 * (Lbar - 50) ** 2) / Math.sqrt(20 + (Lbar - 50) ** 2);
  const SC = 1 + 0.045 * Cpbar;
  const SH = 1 + 0.015 * Cpbar * T;
  const Cp7 = Cpbar ** 7;
  const RT = -2 * Math.sqrt(Cp7 / (Cp7 + 25 ** 7)) * Math.sin(60 * Math.exp(-(((hbar - 275) / 25) ** 2)) * RAD);
  const l = dL / SL, c = dC / SC, h = dH / SH;
  return Math.sqrt(l * l + c * c + h * h + RT * c * h);
}

/**
 * Delta E 2000 between two curves `a`, `b` (n x [r, g, b], linear ACEScg)
 * at the angles `theta` (degrees): {mean, max, atDeg} (the angle of the max).
 */
export function curvesDeltaE(a, b, theta) {
  if (a.length !== b.length || a.length !== theta.length) {
    throw new Error(`the curves have ${a.length} and ${b.length} samples for ${theta.length} angles`);
  }
  let sum = 0, max = -1, atDeg = null;
  for (let i = 0; i < a.length; i++) {
    const dE = delta_E_2000(ACEScg_to_Lab(a[i]), ACEScg_to_Lab(b[i]));
    sum += dE;
    if (dE > max) [max, atDeg] = [dE, theta[i]];
  }
  return { mean: sum / a.length, max, atDeg };
}
