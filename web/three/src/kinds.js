// The model kinds the package draws: generated/kinds.js, written from the
// project's registry (fitting/models/kinds.py) by `python -m
// preview_shaders.three_package`. Each kind's extension object is checked
// and its coefficients packed from its parameters and maxDegree, and drawn
// by its generated GLSL; no kind is named here.

import { DEFAULT_KIND, MODEL_KINDS } from "./generated/kinds.js";

export { DEFAULT_KIND, MODEL_KINDS };

/** The kinds' names, in the registry's order. */
export const KINDS = Object.freeze(MODEL_KINDS.map((kind) => kind.name));

const BY_NAME = new Map(MODEL_KINDS.map((kind) => [kind.name, kind]));
const FLOAT16_MAX = 65504;
// A coat index this far outside a polynomial kind's fitted range (float32
// rounding of the stored range) counts as inside (fitting/exports/gltf_coated.py).
const RANGE_SLACK = 1e-6;

/** The kind called `name`, or undefined. */
export const kindNamed = (name) => BY_NAME.get(name);

const article = (name) => (/^[aeiou]/i.test(name) ? "an" : "a");

/** A parameter's sign rule in words ("n > 0"), or its name alone. */
function rule(kind, p) {
  if (p in kind.exclusiveMinimum) return `${p} > ${kind.exclusiveMinimum[p]}`;
  if (p in kind.minimum) return `${p} >= ${kind.minimum[p]}`;
  return p;
}

/** Whether `x` keeps parameter `p`'s sign rule of `kind`. */
function keeps(kind, p, x) {
  if (p in kind.exclusiveMinimum) return x > kind.exclusiveMinimum[p];
  if (p in kind.minimum) return x >= kind.minimum[p];
  return true;
}

/**
 * Check the kind's own fields of extension object `model` (its `degree`,
 * `coefficients`, and for a kind polynomial in the coat index the coat's
 * index `model.coatIor` inside etaIRange); `fail(what)` throws naming the
 * field and the rule.
 */
export function checkKindFields(kind, model, fail) {
  const C = model.coefficients;
  if (!C || typeof C !== "object" || Array.isArray(C)) fail("`coefficients` must be an object");
  const half = (x) => Number.isFinite(x) && Math.abs(x) <= FLOAT16_MAX;
  const numbers = (row, n, p) => Array.isArray(row) && row.length === n && row.every((x) => half(x) && keeps(kind, p, x));
  if (kind.maxDegree === 0) {
    if (!kind.parameters.every((p) => numbers(C[p], 3, p))) {
      fail(`\`coefficients\` of ${article(kind.name)} ${kind.name} must be ${kind.parameters.map((p) => rule(kind, p)).join(" and ")}, three float16 numbers each`);
    }
    return;
  }
  const [lo, hi] = model.etaIRange;
  const eta = model.coatIor;
  if (!(eta >= lo - RANGE_SLACK && eta <= hi + RANGE_SLACK)) {
    fail(`the coat's index ${eta} lies outside the ${kind.name}'s etaIRange [${lo}, ${hi}]`);
  }
  const d = model.degree;
  if (!(Number.isInteger(d) && d >= 0 && d <= kind.maxDegree)) {
    fail(`\`degree\` must be an integer from 0 to ${kind.maxDegree}, got ${JSON.stringify(d)}`);
  }
  for (const p of kind.parameters) {
    if (!Array.isArray(C[p]) || C[p].length !== 3 || !C[p].every((row) => numbers(row, d + 1, p))) {
      const sign = rule(kind, p) === p ? "" : ` (${rule(kind, p)})`;
      fail(`\`coefficients.${p}\` must be three rows of ${d + 1} float16 numbers${sign}`);
    }
  }
}
