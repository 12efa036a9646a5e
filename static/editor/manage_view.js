// The materials an artist manages (state.saved, state.bin, state.versions):
// the saved edited materials (uploads and drafts apart), each to open (with
// its edit: its base and edited curves, as a link reopens it),
// rename (in place: Enter keeps, Escape drops), delete (to the bin), list
// its versions or copy its link; the bin with Restore; a material's
// versions, each to open, download (in the Download menu's format as it is
// at the click, as the fit's own Download) or compare with the fit on
// screen. Every saved material is listed (each page of GET /materials); the
// search box asks the service (?q=) and lists what it found. Renders from
// the state; hooks:
//   onSearch(query), onOpen(material), onRename(material, name), onDelete(material),
//   onRestore(material), onVersions(material), onLink(fitId),
//   onOpenVersion(entry), onCompareVersion(entry), downloadURL(fitId).

const $ = (id) => document.getElementById(id);

const when = (seconds) => new Date(seconds * 1000).toLocaleString("en-GB", { dateStyle: "medium", timeStyle: "short" });

function button(text, label, click) {
  const node = document.createElement("button");
  node.type = "button";
  node.textContent = text;
  node.setAttribute("aria-label", label);
  node.addEventListener("click", click);
  return node;
}

function line(title, meta, actions, current = false) {
  const li = document.createElement("li");
  li.classList.toggle("current", current);
  const name = document.createElement("span");
  name.className = "title";
  name.textContent = title;
  const buttons = document.createElement("span");
  buttons.className = "actions";
  buttons.append(...actions);
  const info = document.createElement("span");
  info.className = "meta";
  info.textContent = meta;
  li.append(name, buttons, info);
  return li;
}

/** The saved materials to list: those the service found (in the list's order), or all. */
export function shownSaved(saved, found) {
  if (!found) return saved;
  const ids = new Set(found);
  return saved.filter((m) => ids.has(m.id));
}

export class ManageView {
  constructor(hooks) {
    this.hooks = hooks;
    this.renaming = null; // the id of the material being renamed
    $("saved-search").addEventListener("input", (event) => this.hooks.onSearch(event.target.value));
  }

  render(state) {
    const open = state.base && state.base.kind === "curves" ? state.base.material_id : null;
    const shown = shownSaved(state.saved, state.savedSearch.found);
    const { query } = state.savedSearch;
    $("saved-state").textContent = state.savedSearch.found
      ? `${shown.length} of ${state.saved.length} match “${query.trim()}”.`
      : `${state.saved.length} saved material${state.saved.length === 1 ? "" : "s"}.`;
    $("saved-list").replaceChildren(...shown.map((m) => this.#saved(m, m.id === open)));
    if (!state.saved.length) $("saved-list").append(line("Nothing saved yet", "Edit a curve and press Save.", []));
    $("bin-count").textContent = String(state.bin.length);
    $("bin-list").replaceChildren(...state.bin.map((m) => {
      const li = line(m.name, `deleted ${when(m.deleted_at)} · ${m.version} version${m.version === 1 ? "" : "s"}`,
                      [button("Restore", `Restore ${m.name}`, () => this.hooks.onRestore(m))]);
      li.dataset.id = m.id;
      return li;
    }));
    this.#versions(state.versions);
  }

  #saved(m, current) {
    if (this.renaming === m.id) return this.#renameLine(m);
    const li = line(m.name, `${m.version} version${m.version === 1 ? "" : "s"} · ${m.id.slice(0, 8)}`, [
      button("Open", `Open ${m.name}`, () => this.hooks.onOpen(m)),
      button("Rename", `Rename ${m.name}`, () => {
        this.renaming = m.id;
        this.hooks.rerender();
      }),
      button("Versions", `Versions of ${m.name}`, () => this.hooks.onVersions(m)),
      button("Link", `Copy the link to ${m.name}`, () => this.hooks.onLink(m.latest_fit_id)),
      button("Delete", `Delete ${m.name} (to the bin)`, () => this.hooks.onDelete(m)),
    ], current);
    li.dataset.id = m.id;
    return li;
  }

  #renameLine(m) {
    const li = document.createElement("li");
    li.dataset.id = m.id;
    const input = document.createElement("input");
    input.type = "text";
    input.maxLength = 200;
    input.value = m.name;
    input.setAttribute("aria-label", `New name of ${m.name}`);
    const done = (keep) => {
      this.renaming = null;
      if (keep && input.value.trim() && input.value.trim() !== m.name) this.hooks.onRename(m, input.value.trim());
      else this.hooks.rerender();
    };
    input.addEventListener("keydown", (event) => {
      if (event.key === "Enter") done(true);
      if (event.key === "Escape") done(false);
    });
    const actions = document.createElement("span");
    actions.className = "actions";
    actions.append(button("Keep", "Keep the new name", () => done(true)), button("Cancel", "Keep the old name", () => done(false)));
    li.append(input, actions);
    queueMicrotask(() => input.select());
    return li;
  }

  /** The versions' download links again, in the Download menu's format (when it changes). */
  showDownloads() {
    for (const link of $("versions-list").querySelectorAll("a[data-fit]")) link.href = this.hooks.downloadURL(link.dataset.fit);
  }

  #versions(listed) {
    $("versions").hidden = !listed;
    if (!listed) return;
    $("versions-heading").textContent = `Versions of “${listed.material.name}”`;
    $("versions-list").replaceChildren(...listed.list.map((v) => {
      const download = document.createElement("a");
      download.className = "button";
      download.textContent = "Download";
      download.dataset.fit = v.fit_id;
      download.href = this.hooks.downloadURL(v.fit_id);
      // The href is set again at the click: the Download menu (and an export's settings) as they are then.
      download.addEventListener("click", () => { download.href = this.hooks.downloadURL(v.fit_id); });
      download.setAttribute("download", "");
      download.setAttribute("aria-label", `Download version ${v.version}`);
      const figure = v.delta_E_mean === null ? "" : ` · ΔE₀₀ ${v.delta_E_mean.toFixed(2)}` +
        (v.delta_E_max === null || v.delta_E_max === undefined ? "" : `, max ${v.delta_E_max.toFixed(2)}`);
      const li = line(`v${v.version}${v.version === listed.latest ? " (latest)" : ""}`,
                      `${when(v.saved_at)} · “${v.name}”${figure}`, [
        button("Open", `Open version ${v.version}`, () => this.hooks.onOpenVersion(v)),
        download,
        button("Compare", `Compare version ${v.version} with the fit on screen`, () => this.hooks.onCompareVersion(v)),
        button("Link", `Copy the link to version ${v.version}`, () => this.hooks.onLink(v.fit_id)),
      ]);
      li.dataset.version = v.version;
      return li;
    }));
  }
}
