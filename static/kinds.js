// The model kinds the browser draws, as GET /api/v1/domain serves them
// (model_kinds, default_model: the registry of fitting/models/kinds.py,
// a plugin's kinds among them; setModelKinds takes that answer): for each
// kind how its coefficients become the words a renderer uploads (its
// parameters, channel R, G, B, then power, two float16 halves a word), the
// GLSL the preview includes to draw it (cf_preview_model.glsl, generated
// from the registry) and how the editor writes its coefficients out. No
// kind is named here; a fit of a kind the server did not list is refused by
// name (modelKind), never drawn as another kind.
//
// No DOM, no WebGL: imported by the preview (preview.js, splitsum.js), the
// editor's views, and by the node unit tests.

// ------------------------------------------------------------ float16 halves

const f32 = new Float32Array(1);
const u32 = new Uint32Array(f32.buffer);

/** IEEE half bits of `x`, rounded to nearest even (exact for float16 values). */
export function halfBits(x) {
  f32[0] = x;
  const bits = u32[0];
  const sign = (bits >>> 16) & 0x8000;
  const exponent = (bits >>> 23) & 0xff;
  let mantissa = bits & 0x7fffff;
  if (exponent === 0xff) return sign | 0x7c00 | (mantissa ? 0x200 : 0);
  const e = exponent - 112;
  if (e >= 0x1f) return sign | 0x7c00;
  if (e <= 0) {
    if (e < -10) return sign;
    mantissa |= 0x800000;
    const shift = 14 - e;
    let h = mantissa >>> shift;
    const rest = mantissa & ((1 << shift) - 1), half = 1 << (shift - 1);
    if (rest > half || (rest === half && (h & 1))) h += 1;
    return sign | h;
  }
  let h = (e << 10) | (mantissa >>> 13);
  const rest = mantissa & 0x1fff;
  if (rest > 0x1000 || (rest === 0x1000 && (h & 1))) h += 1;
  return sign | h;
}

/** Halves two to a uint32 word, the earlier in the low 16 bits (fitting.pack.halves_to_uint32), padded to `count` words. */
export function wordsOf(halves, count = 14) {
  const words = new Uint32Array(count);
  for (let k = 0; 2 * k < halves.length && k < count; k++) {
    words[k] = ((halves[2 * k] ?? 0) | ((halves[2 * k + 1] ?? 0) << 16)) >>> 0;
  }
  return words;
}

/**
 * The 14 uint32 words of coefficients of a kind with `parameters` and
 * `maxDegree` (a ModelKindPublic's): for each parameter, channel R, G, B,
 * its value (maxDegree 0) or its maxDegree + 1 powers, those beyond the
 * fit's degree 0 (preview_shaders.kinds.preview_words).
 */
export function wordsFor({ parameters, maxDegree }, coefficients) {
  const halves = [];
  for (const p of parameters) {
    for (let c = 0; c < 3; c++) {
      if (maxDegree === 0) halves.push(halfBits(coefficients[p][c]));
      else for (let j = 0; j <= maxDegree; j++) halves.push(halfBits(coefficients[p][c][j] ?? 0));
    }
  }
  return wordsOf(halves);
}

const row = (values) => values.map((v) => v.toFixed(5)).join(", ");

// ------------------------------------------------------------ the registry

/** The name of the include each kind's `glsl` is (shader_ball.frag, model_albedo_table.frag). */
export const PREVIEW_MODEL_FILE = "cf_preview_model.glsl";

const KINDS = new Map(); // name -> kind (see kindOf)
let defaultName = null;

// A ModelKindPublic of GET /domain as the browser uses it.
function kindOf(k) {
  const parameters = [...k.parameters], maxDegree = k.max_degree;
  const rowOk = (r) => (maxDegree === 0
    ? Number.isFinite(r)
    : Array.isArray(r) && r.length >= 1 && r.length <= maxDegree + 1 && r.every(Number.isFinite));
  return Object.freeze({
    name: k.name,
    description: k.description,
    /**
     * The editor's own solver of this kind's live step, as the server
     * names it (`live_solver`: editor/live_page.js's table), or null: the
     * editor asks the server's live step (a plugin's kind).
     */
    liveSolver: k.live_solver ?? null,
    parameters,
    maxDegree,
    splitSum: k.split_sum,
    /** Generated includes by name, for glpass.fullscreenProgram. */
    sources: Object.freeze({ [PREVIEW_MODEL_FILE]: k.glsl }),
    /** Uint32Array(14): what the preview uploads as cf_words. */
    words: (coefficients) => wordsFor({ parameters, maxDegree }, coefficients),
    /** Throws an Error naming the field when `coefficients` are malformed. */
    check(C) {
      const rows = maxDegree === 0 ? "three numbers (R, G, B)" : `three rows of 1 to ${maxDegree + 1} numbers`;
      for (const p of parameters) {
        if (!Array.isArray(C[p]) || C[p].length !== 3 || !C[p].every(rowOk)) {
          throw new Error(`\`coefficients.${p}\` of a ${k.name} fit must be ${rows}`);
        }
      }
    },
    /** The editor's text of a fit's coefficients. */
    describe(fit) {
      const head = maxDegree === 0 ? k.name : `${k.name}, degree ${fit.degree}`;
      const rows = parameters.map((p) => `${p.padEnd(5)} ` + fit.coefficients[p].map((r, c) =>
        `${"RGB"[c]} ${maxDegree === 0 ? row([r]) : `[${row(r)}]`}`).join("  "));
      return `${head} (${k.description}), eta_i in [${fit.eta_i_range.join(", ")}]\n${rows.join("\n")}`;
    },
  });
}

/** Take the kinds of a GET /domain answer ({model_kinds, default_model}) as the ones this page draws. */
export function setModelKinds(domain) {
  if (!Array.isArray(domain?.model_kinds) || !domain.model_kinds.length || typeof domain.default_model !== "string") {
    throw new Error("the domain must list `model_kinds` and name `default_model`");
  }
  KINDS.clear();
  for (const k of domain.model_kinds) KINDS.set(k.name, kindOf(k));
  defaultName = domain.default_model;
}

/** Whether setModelKinds has been given the server's kinds. */
export const modelKindsKnown = () => defaultName !== null;

/** The kind of a fit that names none (the server's default_model). */
export const defaultModelKind = () => defaultName;

/** The kinds' names, in the registry's order. */
export const modelKindNames = () => [...KINDS.keys()];

/** The kind called `name` (no coefficients checked); an Error naming `model` for one the server did not list. */
export function modelKindNamed(name) {
  return modelKind({ model: name, coefficients: null });
}

/**
 * The kind of `fit` (a FitPublic answer; no `model` means the default
 * kind), its coefficients checked; an Error naming `model` for a kind this
 * page cannot draw.
 */
export function modelKind(fit) {
  if (!modelKindsKnown()) throw new Error("the model kinds are not known yet (setModelKinds with GET /domain)");
  const name = fit.model ?? defaultName;
  const kind = KINDS.get(name);
  if (!kind) {
    throw new Error(`\`model\` must be one of ${modelKindNames().join(", ")} to be drawn here, got ${JSON.stringify(name)}`);
  }
  if (fit.coefficients !== null) kind.check(fit.coefficients || {});
  return kind;
}
