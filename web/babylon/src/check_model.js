// The checks of an EXT_materials_coated_conductor object: the schema's rules
// (docs/gltf/EXT_materials_coated_conductor/schema/) and the two it cannot
// state, the same as coated-conductor-three's checkModel (the package
// imports nothing outside itself).

export const EXTENSION_NAME = "EXT_materials_coated_conductor";
/** The draft extension carrying the clear coat's index, nested in KHR_materials_clearcoat's object. */
export const CLEARCOAT_IOR = "KHR_materials_clearcoat_ior";
export const KINDS = ["coated-conductor", "rgb-conductor"];

const PROPERTIES = new Set(["kind", "colorSpace", "etaIRange", "degree", "coefficients", "extensions", "extras"]);

/**
 * The coat a glTF material definition composes the extension with:
 * {factor, ior}: its KHR_materials_clearcoat's clearcoatFactor and the
 * nested KHR_materials_clearcoat_ior's clearcoatIor (1.5 without it); no
 * clear coat, or a factor of 0, is no coat, {factor: 0, ior: 1}.
 */
export function coatOf(definition) {
  const clearcoat = definition?.extensions?.KHR_materials_clearcoat;
  const factor = clearcoat && typeof clearcoat === "object" ? clearcoat.clearcoatFactor ?? 0 : 0;
  if (!(factor > 0)) return { factor: 0, ior: 1 };
  return { factor, ior: clearcoat.extensions?.[CLEARCOAT_IOR]?.clearcoatIor ?? 1.5 };
}
const FLOAT16_MAX = 65504;
// A coat index this far outside a coated-conductor's fitted range (float32
// rounding of the stored range) counts as inside (fitting/exports/gltf_coated.py).
const RANGE_SLACK = 1e-6;

/**
 * The extension object `model` if it is one this module draws under a coat
 * of index `coatIor` (default 1.5; 1: no coat); else an Error naming the
 * field and the rule: the schema's rules
 * (docs/gltf/EXT_materials_coated_conductor/schema/) and the two it cannot
 * state (lo <= hi; a coated-conductor's coat index inside etaIRange).
 */
export function checkModel(model, coatIor = 1.5) {
  const fail = (what) => { throw new Error(`${EXTENSION_NAME}: ${what}`); };
  if (!model || typeof model !== "object" || Array.isArray(model)) fail("the extension must be an object");
  for (const key of Object.keys(model)) {
    if (!PROPERTIES.has(key)) fail(`\`${key}\` is not a property of the extension`);
  }
  if (!KINDS.includes(model.kind)) fail(`\`kind\` must be one of ${KINDS.join(", ")}, got ${JSON.stringify(model.kind)}`);
  if (model.colorSpace !== "ACEScg") fail(`\`colorSpace\` must be "ACEScg", got ${JSON.stringify(model.colorSpace)}`);
  const index = (x) => typeof x === "number" && x >= 1 && x <= 3;
  const range = model.etaIRange;
  if (!Array.isArray(range) || range.length !== 2 || !range.every(index) || !(range[0] <= range[1])) {
    fail(`\`etaIRange\` must be [lo, hi] with 1 <= lo <= hi <= 3, got ${JSON.stringify(range)}`);
  }
  const eta = coatIor;
  if (!index(eta)) {
    fail(`the coat's index (${CLEARCOAT_IOR} \`clearcoatIor\`) must lie in [1, 3], got ${JSON.stringify(eta)}`);
  }
  const C = model.coefficients;
  if (!C || typeof C !== "object" || Array.isArray(C)) fail("`coefficients` must be an object");
  const half = (x) => Number.isFinite(x) && Math.abs(x) <= FLOAT16_MAX;
  const numbers = (row, n) => Array.isArray(row) && row.length === n && row.every(half);
  if (model.kind === "rgb-conductor") {
    if (!numbers(C.n, 3) || !numbers(C.k, 3) || !C.n.every((x) => x > 0) || !C.k.every((x) => x >= 0)) {
      fail("`coefficients` of an rgb-conductor must be n > 0 and k >= 0, three float16 numbers each");
    }
  } else {
    const [lo, hi] = range;
    if (!(eta >= lo - RANGE_SLACK && eta <= hi + RANGE_SLACK)) {
      fail(`the coat's index ${eta} lies outside the coated-conductor's etaIRange [${lo}, ${hi}]`);
    }
    const d = model.degree;
    if (![0, 1, 2].includes(d)) fail(`\`degree\` must be 0, 1 or 2, got ${JSON.stringify(d)}`);
    for (const p of ["F0", "a", "alpha"]) {
      if (!Array.isArray(C[p]) || C[p].length !== 3 || !C[p].every((row) => numbers(row, d + 1))) {
        fail(`\`coefficients.${p}\` must be three rows of ${d + 1} float16 numbers`);
      }
    }
  }
  return model;
}
