// The library to browse: the built-in conductors (GET /library at the
// preview's eta_i, state.library) with a search box, each with its full
// name and symbol, a swatch (the spectral reference under the coat at 0,
// 45, 70 and 85 degrees as a gradient: the service's swatch.srgb), the
// data's source and its wavelength range. Open makes it the base; Compare
// puts it beside the fit on screen. Renders from the state; hooks:
//   onOpen(symbol), onCompare(symbol).

import { key } from "./state.js";

const $ = (id) => document.getElementById(id);

/**
 * The entries holding every word of `query` (case-insensitive) in their
 * symbol, full name or source: the service's rule for `GET /library?q=`.
 */
export function searchLibrary(materials, query) {
  const words = query.toLowerCase().split(/\s+/).filter(Boolean);
  return materials.filter((m) => {
    const text = `${m.symbol}\n${m.name}\n${m.source}`.toLowerCase();
    return words.every((word) => text.includes(word));
  });
}

const nm = (v) => Math.round(v).toLocaleString("en");

export class LibraryView {
  constructor(hooks) {
    this.hooks = hooks;
    this.state = null;
    $("library-search").addEventListener("input", () => this.state && this.render(this.state));
  }

  render(state) {
    this.state = state;
    const { eta, materials } = state.library;
    const list = $("library-list");
    if (eta === null) {
      $("library-state").textContent = "Loading the library…";
      return;
    }
    const query = $("library-search").value;
    const found = searchLibrary(materials, query);
    const signature = `${eta}|${query}|${state.base ? state.base.id : ""}|${found.map((m) => m.id).join()}`;
    $("library-state").textContent = query.trim()
      ? `${found.length} of ${materials.length} match “${query.trim()}”; swatches under a coat of ηᵢ ${eta}.`
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
    const actions = document.createElement("span");
    actions.className = "actions";
    actions.append(this.#button("Open", `Open ${m.name} as the base`, () => this.hooks.onOpen(m.id)),
                   this.#button("Compare", `Compare the fit on screen with ${m.name}`, () => this.hooks.onCompare(m.id)));
    const meta = document.createElement("span");
    meta.className = "meta";
    const [lo, hi] = m.wavelength_range_nm;
    meta.textContent = `${m.source.split("\n")[0]} · ${nm(lo)}–${nm(hi)} nm`;
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
