// The editor's state: one object, changed only by the named actions below
// (store.dispatch(name, payload)); the views render from it. No DOM, no
// fetch: node --test runs it (tests/static/js/state.test.mjs).
//
// Edits are target curves by coating index: edits[key(eta_i)] is SAMPLES x
// 3 rgb at the angles `theta`. Undo and redo hold snapshots of the edits
// (JSON strings), so every change of the edits is undoable and a snapshot
// names exactly what a refit fitted.

import { DEFAULT_FALLOFF, falloffWeight } from "./falloff.js";

export const SAMPLES = 46; // 0, 2, ..., 90 degrees
export const HANDLES = [0, 20, 36, 50, 60, 70, 78, 84]; // the control points' angles

/** The key of a coating index in `edits` (two decimals). */
export const key = (eta) => Number(eta).toFixed(2);

export function initialState() {
  return {
    base: null,       // the fit being edited (a FitPublic answer)
    fit: null,        // the fit on screen: id, figures, curves and preview show it
    shownEdits: "{}", // the snapshot of the edits the fit on screen was fitted to
    savedId: null,    // the fit last saved from this base
    eta: 1.5,
    edits: {},
    falloff: DEFAULT_FALLOFF, // how far a dragged point reaches (falloff.js: none, narrow, wide)
    undo: [],
    redo: [],
    dragStart: null,  // the snapshot before the drag under way
    pointerDrag: false, // a pointer drags a point: refits are live
    theta: [],        // the angles of the curves (degrees)
    baseCurves: null, // the base's curves at `eta` (reference, Lazanyi, model)
    model: null,      // the fit on screen's curve at `eta`
    onScreen: "server", // whose fit the curve and preview show: "server", or "page" (a live refit in the page)
    selected: null,   // the control point typed entry changes: {channel, handle}
    compare: null,    // compare mode: {fit, label, model: its curve at `eta` (or null while it loads)}
    // GET /library at an eta_i; found: ?q= ids, best first; suggested: what a ?q= that found none may have meant
    library: { eta: null, materials: [], query: "", found: null, suggested: [] },
    saved: [],        // the artist's saved edited materials (kind curves), every page
    savedSearch: { query: "", found: null }, // GET /materials?kind=curves&q=: the ids found (null: no search)
    bin: [],          // the saved materials in the bin
    versions: null,   // the versions listed: {material: {id, name}, list: newest first}
    presets: [],      // coat presets ({id, name, eta_i, source})
  };
}

/** The edits as a string: what undo keeps and what a refit is asked for. */
export const snapshot = (s) => JSON.stringify(s.edits);

/** Whether there are edits and the fit on screen is not the one saved (refits are drafts). */
export const unsaved = (s) => Object.keys(s.edits).length > 0 && s.fit !== null && s.savedId !== s.fit.id;

/** Whether the fit on screen is the fit of the edits on screen. */
export const fitted = (s) => s.fit !== null && s.shownEdits === snapshot(s);

/**
 * The curve an edit at the current eta_i starts from: the edit itself, or
 * for a saved edit (a curve fit) its own model, else the measured reference.
 */
export function target(s) {
  const edit = s.edits[key(s.eta)];
  if (edit) return edit;
  if (!s.baseCurves) return null;
  if (s.base.kind === "curves") return s.baseCurves.model;
  return s.baseCurves.reference || s.baseCurves.model;
}

/** The live refit's start: the fit on screen (or the base) while a pointer drags, else null (a full refit). */
export const liveStart = (s) => (s.pointerDrag ? (s.fit || s.base).id : null);

const clamp01 = (v) => Math.min(1, Math.max(0, v));

/**
 * The edits of a stored curve fit's request (GET /fits/{id}/edit:
 * `request.curves`, each {eta_i, angle_deg | cos_theta, rgb}) at the
 * editor's angles `theta` (degrees): each curve interpolated linearly in
 * angle (held flat past its ends), keyed by key(eta_i).
 */
export function editsOf(curves, theta) {
  const edits = {};
  for (const curve of curves) {
    const angles = curve.angle_deg || curve.cos_theta.map((mu) => (Math.acos(Math.min(1, Math.max(-1, mu))) * 180) / Math.PI);
    const order = angles.map((a, i) => [a, curve.rgb[i]]).sort((p, q) => p[0] - q[0]);
    edits[key(curve.eta_i)] = theta.map((t) => {
      let j = 0;
      while (j < order.length - 2 && order[j + 1][0] < t) j++;
      const [a0, c0] = order[j], [a1, c1] = order[Math.min(j + 1, order.length - 1)];
      const f = a1 > a0 ? Math.min(1, Math.max(0, (t - a0) / (a1 - a0))) : 0;
      return [0, 1, 2].map((c) => clamp01(c0[c] + f * (c1[c] - c0[c])));
    });
  }
  return edits;
}

/**
 * The curve `current` (rows of rgb at angles `theta`) with the point at
 * `handleDeg` of `channel` moved to `value`, its neighbours as `falloff`
 * says (falloff.js: "none" the point alone, its neighbouring handles
 * kept; "narrow", "wide" a Gaussian; 0 at 90 degrees, where the model is 1
 * whatever its coefficients). One channel moves by the offset; `all` scales the three
 * channels (brightness changes, hue stays). A new array; null when the
 * point is already there.
 */
export function bump(current, theta, handleDeg, channel, value, all = false, falloff = DEFAULT_FALLOFF) {
  const rows = current.map((rgb) => rgb.map(clamp01));
  const i = theta.indexOf(handleDeg);
  if (i < 0) throw new Error(`handle ${handleDeg} is not one of the curve's angles`);
  const before = rows[i][channel];
  if (value === before) return null;
  const delta = value - before;
  const ratio = before > 1e-6 ? value / before : null;
  for (let j = 0; j < theta.length; j++) {
    const w = falloffWeight(theta[j], handleDeg, falloff, HANDLES);
    if (all) {
      const scale = ratio === null ? null : 1 + (ratio - 1) * w;
      for (let c = 0; c < 3; c++) rows[j][c] = clamp01(scale === null ? rows[j][c] + delta * w : rows[j][c] * scale);
    } else {
      rows[j][channel] = clamp01(rows[j][channel] + delta * w);
    }
  }
  return rows;
}

// Push the snapshot `before` on the undo stack (a new change: redo is gone).
function remember(s, before) {
  s.undo.push(before);
  s.redo = [];
}

// A drag or burst of key presses still under way is one undo step before anything else changes the history.
function settleDrag(s) {
  if (s.dragStart !== null) ACTIONS.dragEnd(s);
}

/** The named actions: (state, payload) -> a result (most: whether anything changed). */
export const ACTIONS = {
  /** A new base (FitPublic): no edits, no history; eta_i kept within its domain. */
  openBase(s, fit) {
    Object.assign(s, { base: fit, fit: null, savedId: null, edits: {}, undo: [], redo: [], dragStart: null,
                       pointerDrag: false, shownEdits: "{}" });
    const [lo, hi] = fit.eta_i_range;
    s.eta = Math.min(hi, Math.max(lo, s.eta));
    return true;
  },
  /** The base's curves at the current eta_i ({theta_deg, reference, lazanyi_adjusted, model}) and the fit's. */
  curves(s, { base, model = null }) {
    s.baseCurves = base;
    s.theta = base.theta_deg.map((t) => Math.round(t * 1e6) / 1e6);
    s.model = model ?? base.model;
    return true;
  },
  setEta(s, eta) {
    s.eta = eta;
    return true;
  },
  /**
   * Move a control point ({channel, handle: index into HANDLES, value,
   * pointer: a pointer drags it, all: the three channels}); false when
   * nothing moved or the curves of this eta_i are not in yet.
   */
  drag(s, { channel, handle, value, pointer = false, all = false }) {
    const k = key(s.eta);
    if (!s.baseCurves || key(s.baseCurves.eta_i) !== k) return false;
    const moved = bump(target(s), s.theta, HANDLES[handle], channel, value, all, s.falloff);
    if (!moved) return false;
    if (s.dragStart === null) s.dragStart = snapshot(s);
    s.pointerDrag = pointer;
    s.edits[k] = moved;
    return true;
  },
  /** The drag (or key presses) ended: one undo step for it, refits full again. */
  dragEnd(s) {
    s.pointerDrag = false;
    if (s.dragStart !== null && s.dragStart !== snapshot(s)) remember(s, s.dragStart);
    s.dragStart = null;
    return true;
  },
  undo(s) {
    settleDrag(s);
    if (!s.undo.length) return false;
    s.redo.push(snapshot(s));
    s.edits = JSON.parse(s.undo.pop());
    return true;
  },
  redo(s) {
    settleDrag(s);
    if (!s.redo.length) return false;
    s.undo.push(snapshot(s));
    s.edits = JSON.parse(s.redo.pop());
    return true;
  },
  /** How far the next drags reach ("none", "narrow", "wide"; falloff.js). */
  falloff(s, falloff) {
    falloffWeight(0, HANDLES[0], falloff, HANDLES); // refuses an unknown name
    s.falloff = falloff;
    return true;
  },
  /** A colour edit (colour.js): the edits replaced by the metal's curves ({eta key: rgb rows}; undoable). */
  colour(s, edits) {
    settleDrag(s);
    remember(s, snapshot(s));
    s.edits = edits;
    return true;
  },
  /** Back to no edits (undoable). */
  reset(s) {
    settleDrag(s);
    remember(s, snapshot(s));
    s.edits = {};
    return true;
  },
  /** Every edit halfway back to `starts[eta]`, the curve it started from (undoable). */
  gentler(s, starts) {
    settleDrag(s);
    remember(s, snapshot(s));
    for (const [eta, start] of Object.entries(starts)) {
      s.edits[eta] = s.edits[eta].map((rgb, j) => rgb.map((v, c) => clamp01(start[j][c] + 0.5 * (v - start[j][c]))));
    }
    return true;
  },
  /** The fit shown ({fit, edits: the snapshot it fitted, model: its curve at eta_i or null}). */
  shown(s, { fit, edits = "{}", model = null }) {
    s.fit = fit;
    s.shownEdits = edits;
    s.onScreen = "server";
    if (model) s.model = model;
    return true;
  },
  /**
   * A live refit solved in the page while a point is held ({model: its
   * curve at eta_i}): drawn, never the fit on screen (ids, figures and
   * downloads stay the server's); false once the drag has ended.
   */
  liveShown(s, { model }) {
    if (!s.pointerDrag) return false;
    s.model = model;
    s.onScreen = "page";
    return true;
  },
  saved(s, fitId) {
    s.savedId = fitId;
    return true;
  },
  /** A stored edit reopened (after openBase of its base): its edits, no history; `fitId` is saved. */
  reopened(s, { edits, fitId }) {
    Object.assign(s, { edits, undo: [], redo: [], dragStart: null, pointerDrag: false, savedId: fitId });
    return true;
  },
  /** The control point typed entry changes ({channel, handle: index into HANDLES}). */
  select(s, { channel, handle }) {
    s.selected = { channel, handle };
    return true;
  },
  /** Compare mode: `fit` beside the fit on screen (its curve at eta_i follows with compareCurves). */
  compareWith(s, { fit, label }) {
    s.compare = { fit, label, model: null, eta: null };
    return true;
  },
  /** The compared fit's curve at `eta` (dropped if compare mode changed or ended meanwhile). */
  compareCurves(s, { fitId, eta, model }) {
    if (!s.compare || s.compare.fit.id !== fitId) return false;
    Object.assign(s.compare, { model, eta: key(eta) });
    return true;
  },
  compareOff(s) {
    s.compare = null;
    return true;
  },
  /** The library at an eta_i (GET /library: entries with names, sources, ranges, swatches). */
  library(s, { eta, materials }) {
    s.library = { ...s.library, eta: key(eta), materials };
    return true;
  },
  /** The library's search: the ids GET /library?q= answered for `query`, best first (null: no search),
   *  and, when it found none, the ids it suggested. */
  librarySearch(s, { query, ids, suggested = [] }) {
    const searched = Boolean(query.trim());
    s.library = { ...s.library, query, found: searched ? ids : null, suggested: searched ? suggested : [] };
    return true;
  },
  /** The saved edited materials and the bin. */
  materials(s, { saved, bin }) {
    Object.assign(s, { saved, bin });
    return true;
  },
  /** The search of the saved materials: the ids the service found for `query` (null: no search). */
  savedSearch(s, { query, ids }) {
    s.savedSearch = { query, found: query.trim() ? ids : null };
    return true;
  },
  /** A material's versions ({material: {id, name}, list}), or null to close the list. */
  versions(s, listed) {
    s.versions = listed;
    return true;
  },
  presets(s, presets) {
    s.presets = presets;
    return true;
  },
};

/**
 * The store: `state`, `dispatch(name, payload)` (runs ACTIONS[name], then
 * every subscriber with (name, state, result)), `subscribe(fn)` (returns
 * the unsubscribe).
 */
export function createStore(state = initialState()) {
  const listeners = new Set();
  return {
    state,
    dispatch(name, payload) {
      const action = ACTIONS[name];
      if (!action) throw new Error(`no editor action ${JSON.stringify(name)}`);
      const result = action(state, payload);
      for (const listener of listeners) listener(name, state, result);
      return result;
    },
    subscribe(listener) {
      listeners.add(listener);
      return () => listeners.delete(listener);
    },
  };
}
