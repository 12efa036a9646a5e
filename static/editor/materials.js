// The material picker: the library and every saved material (GET /materials,
// each page followed to the last) in one <select>, the fit behind a picker value, and the material open last
// (localStorage). No state of the editor: what it fetches it returns.

import * as api from "../api.js";

export const LAST_KEY = "coated-editor-material"; // localStorage: the material open last
export const FIRST = "library:Au";

// The picker's groups by kind: the library, the artist's saved edits, uploads (n, k fits) apart.
const GROUPS = { library: "Library", curves: "Saved", nk: "Uploads (n, k)" };

/** Fill `picker` with the material list (Library, Saved, Uploads), `select` chosen. */
export async function loadMaterials(picker, select = null) {
  const materials = await api.listAllMaterials({ kinds: Object.keys(GROUPS) });
  picker.replaceChildren();
  const nodes = {};
  for (const [group, label] of Object.entries(GROUPS)) {
    nodes[group] = document.createElement("optgroup");
    nodes[group].label = label;
    picker.appendChild(nodes[group]);
  }
  for (const m of materials) {
    const option = document.createElement("option");
    const saved = m.kind !== "library";
    option.value = saved ? `saved:${m.id}` : `library:${m.id}`;
    option.textContent = saved ? `${m.name} (${m.kind === "curves" ? "edited" : "n, k"})` : m.name;
    option.dataset.source = m.source || "";
    nodes[m.kind].appendChild(option);
  }
  for (const node of Object.values(nodes)) if (!node.children.length) node.remove();
  if (select) picker.value = select;
  return materials;
}

/** The fit of a picker value (a library fit is made or served from the store; a saved material's latest fit). */
export async function fitOf(value) {
  const [kind, id] = value.split(/:(.*)/s);
  if (kind === "library") return api.fitLibrary(id, [1.0, 2.5]);
  const material = await api.getMaterial(id);
  versions.set(material.latest_fit.id, material.version);
  return material.latest_fit;
}

// The version of a saved material as its fit was read (fitOf): a save continues from it.
const versions = new Map();

/** The material's version when `fit` (its latest) was opened; null when not known. */
export const savedVersion = (fit) => (versions.has(fit.id) ? versions.get(fit.id) : null);

export function remember(value) {
  try {
    localStorage.setItem(LAST_KEY, value);
  } catch (_) {
    // storage disabled: the editor opens Au next time
  }
}

export function recall() {
  try {
    return localStorage.getItem(LAST_KEY);
  } catch (_) {
    return null; // storage disabled
  }
}

/**
 * The curves at `eta` and the reference texture of `fit`, asked for at
 * once (the cold start: while the preview's shaders compile); {eta, curves,
 * texture} promises, each used or asked again (their failures are muted).
 */
export function prefetch(fit, eta, samples) {
  const early = {
    eta,
    curves: api.curves(fit.id, eta, samples),
    texture: fit.has_nk ? api.referenceTexture(fit.id) : null,
  };
  for (const promise of [early.curves, early.texture]) if (promise) promise.catch(() => {});
  return early;
}
