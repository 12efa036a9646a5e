// The library to browse: every conductor of the catalogue (GET /library at
// the preview's eta_i, state.library), each with its common name, symbol and
// category, a swatch (the spectral reference under the coat at 0, 45, 70 and
// 85 degrees as a gradient: the service's swatch.srgb), the page's label and
// its wavelength range. The search box asks the service (GET /library?q=:
// names and symbols first, never inside a citation) and shows its order.
// Open makes one the base; Compare puts it beside the fit on screen. Renders
// from the state; hooks: onOpen(id), onCompare(id), onSearch(query).

import { key } from "./state.js";

const $ = (id) => document.getElementById(id);

/** The entries to list: the service's matches for the search, best first, or all of them. */
export function shownLibrary({ materials, found }) {
  if (!found) return materials;
  const byId = new Map(materials.map((m) => [m.id, m]));
  return found.map((id) => byId.get(id)).filter(Boolean);
}

const nm = (v) => Math.round(v).toLocaleString("en");

export class LibraryView {
  constructor(hooks) {
    this.hooks = hooks;
    this.state = null;
    $("library-search").addEventListener("input", (event) => this.hooks.onSearch(event.target.value));
  }

  render(state) {
    this.state = state;
    const { eta, materials } = state.library;
    const list = $("library-list");
    if (eta === null) {
      $("library-state").textContent = "Loading the library…";
      return;
    }
    const query = state.library.found ? state.library.query : "";
    const matched = shownLibrary(state.library);
    // A search that found none lists what the service suggested (the search less a word, a near spelling).
    const suggested = query.trim() && !matched.length
      ? shownLibrary({ materials, found: state.library.suggested }) : [];
    const found = suggested.length ? suggested : matched;
    const signature = `${eta}|${query}|${state.base ? state.base.id : ""}|${found.map((m) => m.id).join()}`;
    $("library-state").textContent = suggested.length
      ? `No conductor matches “${query.trim()}”; did you mean one of these? ` +
        `Swatches under a coat of ηᵢ ${eta}.`
      : query.trim()
        ? `${found.length} of ${materials.length} match “${query.trim()}”, names and symbols first; ` +
          `swatches under a coat of ηᵢ ${eta}.`
        : `${materials.length} conductors; swatches under a coat of ηᵢ ${eta} (0°, 45°, 70°, 85°).`;
    list.dataset.eta = eta;
    if (signature === this.signature) return;
    this.signature = signature;
    const open = state.base && state.base.kind === "library" ? state.base.material_id || state.base.name : null;
    list.replaceChildren(...found.map((m) => this.#item(m, m.id === open || m.symbol === open)));
  }

  #item(m, current) {
    const li = document.createElement("li");
    li.dataset.id = m.id;
    li.classList.toggle("current", current);
    const swatch = document.createElement("span");
    swatch.className = "chip-swatch";
    swatch.style.background = `linear-gradient(135deg, ${m.swatch.srgb.join(", ")})`;
    swatch.dataset.srgb = m.swatch.srgb[0];
    swatch.title = `Under a coat of ηᵢ ${key(m.swatch.eta_i)} at ${m.swatch.angles_deg.join("°, ")}° (sRGB)`;
    const title = document.createElement("span");
    title.className = "title";
    title.textContent = `${m.name} (${m.symbol})`;
    title.title = m.category;
    const actions = document.createElement("span");
    actions.className = "actions";
    actions.append(this.#button("Open", `Open ${m.name} as the base`, () => this.hooks.onOpen(m.id)),
                   this.#button("Compare", `Compare the fit on screen with ${m.name}`, () => this.hooks.onCompare(m.id)));
    const meta = document.createElement("span");
    meta.className = "meta";
    const [lo, hi] = m.wavelength_range_nm;
    meta.textContent = `${m.category} · ${m.label} · ${nm(lo)}–${nm(hi)} nm`;
    meta.title = m.reference;
    li.append(swatch, title, actions, meta);
    return li;
  }

  #button(text, label, click) {
    const button = document.createElement("button");
    button.type = "button";
    button.textContent = text;
    button.setAttribute("aria-label", label);
    button.addEventListener("click", click);
    return button;
  }
}
