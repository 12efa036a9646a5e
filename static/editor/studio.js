// The editor an artist keeps open all day: the library to
// browse (library_view.js), coat presets and typed entry (entry_view.js),
// the materials an artist manages (manage_view.js: rename, delete and the
// bin, versions, links) and compare mode (compare_view.js, with the
// preview's second ball and the plot's overlaid curves). It composes those
// views as editor.js composes the rest: the views render from the one
// state, their inputs call hooks that become actions and API calls here.
//
// Links: `/?fit={id}` (the Link buttons) reopens a stored fit with its edit
// (GET /fits/{id}/edit: its base, its edited curves as the edits, the
// material it continues); `/?material={id}` (`&version={n}`), the service's
// share_url, opens a material's latest (or that) version the same way.
//
// `app` (editor.js): store, say(text, ok), report(error, retry, prefix),
// guard(work), busy(text, work), setBase(fit), present(fit, curves,
// edits), setEta(eta), edit(payload) (a point moved and released: one undo
// step, a refit), open(value) (a picker value, asking before discarding
// unsaved edits), mayDiscard(), picked(value), reloadPicker(value),
// sayUpload(text, ok), continuing (save.js), previewView, plotView,
// downloadFormat(), exportSettings() (the preview's {etaI, roughness,
// coatRoughness}: an export of a version takes them, as the fit's Download).

import * as api from "../api.js";
import { CompareView } from "./compare_view.js";
import { EntryView } from "./entry_view.js";
import { LibraryView } from "./library_view.js";
import { ManageView } from "./manage_view.js";
import { SAMPLES, editsOf, key, snapshot, unsaved } from "./state.js";

const $ = (id) => document.getElementById(id);

/** The link in a query string: {fit}, {material, version (or null)}, or null. */
export function linkOf(search) {
  const query = new URLSearchParams(search);
  if (query.get("fit")) return { fit: query.get("fit") };
  if (query.get("material")) return { material: query.get("material"), version: Number(query.get("version")) || null };
  return null;
}

/**
 * What a link to an unsaved edit must say: it opens a draft, which the
 * service keeps `ttlSeconds` from when the link was made (`expiresAt`, the
 * link's answer; then it is gone unless saved), and when.
 */
export function draftExpiry(expiresAt, ttlSeconds) {
  if (!ttlSeconds || !expiresAt) return " It opens an unsaved edit: save it to keep the link working.";
  const until = new Date(expiresAt * 1000);
  const when = until.toLocaleString("en-GB", { dateStyle: "medium", timeStyle: "short" });
  const hours = Math.round(ttlSeconds / 3600);
  return ` It opens an unsaved edit, kept ${hours} h: it expires ${when}. Save to keep it.`;
}

/** The link that reopens the stored fit `fitId` with its edit. */
export const linkTo = (fitId, origin) => `${origin}/?fit=${encodeURIComponent(fitId)}`;

// Which views follow which actions (the plot's compare overlay too).
const FOLLOWS = {
  entry: new Set(["openBase", "curves", "setEta", "select", "drag", "dragEnd", "undo", "redo", "reset", "gentler",
                  "presets", "reopened"]),
  library: new Set(["library", "librarySearch", "openBase"]),
  manage: new Set(["materials", "savedSearch", "versions", "openBase"]),
  compare: new Set(["compareWith", "compareCurves", "compareOff", "shown", "curves", "setEta"]),
};

export class Studio {
  constructor(app) {
    this.app = app;
    const state = (this.state = app.store.state);
    const { guard } = app;
    this.timers = {};
    this.entry = new EntryView({ onEta: (eta) => app.setEta(eta), onPoint: (payload) => app.edit(payload) });
    this.library = new LibraryView({
      onOpen: guard((id) => app.open(`library:${id}`)),
      onCompare: guard(async (id) => this.compare(await api.fitLibrary(id, [1.0, 2.5]), `${id} (library)`)),
      onSearch: (query) => this.#later("search", 120, () => this.#search(query)),
    });
    this.manage = new ManageView({
      rerender: () => this.manage.render(state),
      onOpen: guard((m) => app.mayDiscard() && this.openFit(m.latest_fit_id)),
      onRename: guard((m, name) => this.rename(m, name)),
      onDelete: guard((m) => this.remove(m)),
      onRestore: guard((m) => this.restore(m)),
      onVersions: guard((m) => this.versions(m)),
      onLink: guard((fitId) => this.copyLink(fitId)),
      onOpenVersion: guard((v) => app.mayDiscard() && this.openFit(v.fit_id)),
      onCompareVersion: guard(async (v) => this.compare(await api.getFit(v.fit_id), `version ${v.version}`)),
      downloadURL: (fitId) => api.packURL(fitId, app.downloadFormat(), app.exportSettings()),
      onSearch: (query) => this.#later("savedSearch", 120, () => this.#searchSaved(query)),
    });
    $("format").addEventListener("change", () => this.manage.showDownloads());
    this.compareView = new CompareView({
      onCompareBase: guard(() => state.base && this.compare(state.base, "the base (before the edit)")),
      onOff: () => this.compare(null),
    });
    $("copy-link").addEventListener("click", guard(() => state.fit && this.copyLink(state.fit.id)));
    app.store.subscribe((name) => this.#follow(name));
    this.loading = null; // the studio's lists load once the first fit is on screen (never ahead of it: cold start)
    this.refreshes = 0; // refresh() calls so far: only the latest one's lists are shown
    this.turns = Promise.resolve(); // the rename, delete and restore actions, one at a time in the order asked
  }

  #follow(name) {
    const state = this.state;
    if (FOLLOWS.entry.has(name)) this.entry.render(state);
    if (FOLLOWS.library.has(name)) this.library.render(state);
    if (FOLLOWS.manage.has(name)) this.manage.render(state);
    if (FOLLOWS.compare.has(name)) this.compareView.render(state);
    if (name === "compareCurves" || name === "compareOff") this.app.plotView.render(state);
    if (name === "shown") $("share-link").value = linkTo(state.fit.id, location.origin);
    if (name === "shown" && !this.loading) this.loading = this.app.guard(() => this.#load())();
    // The library's swatches and the compared curve follow eta_i (after the slider rests).
    if ((name === "setEta" || name === "openBase") && this.loading) this.#later("library", 400, () => this.#library());
    if (name === "setEta" || name === "compareWith") this.#later("compare", 120, () => this.#compareCurves());
  }

  #later(what, ms, work) {
    clearTimeout(this.timers[what]);
    this.timers[what] = setTimeout(() => work().catch((error) => this.app.say(error.message)), ms);
  }

  async #load() {
    const [presets, domain] = await Promise.all([api.coatPresets(), api.domain(), this.#library(), this.refresh()]);
    this.app.store.dispatch("presets", presets.presets);
    api.setExportFormats(domain.export_formats);
    $("export-formats").replaceChildren(...domain.export_formats.map(
      ({ name, label }) => Object.assign(document.createElement("option"), { value: name, textContent: label })));
    this.draftTtl = domain.draft_ttl_s;
    const [lo, hi] = domain.visible_range_nm;
    $("upload-rule").textContent = `Measured n, k must cover at least ${Math.round(100 * domain.min_coverage)}% of ` +
      `${lo}–${hi} nm (the colour is integrated over that range; the data are held flat past their ends, ` +
      `so a wider gap would be a guess). Files covering less are refused with the range they cover.`;
  }

  async #library() {
    const eta = this.state.eta;
    if (this.state.library.eta === key(eta)) return;
    const { materials } = await api.library(eta);
    if (key(eta) === key(this.state.eta)) this.app.store.dispatch("library", { eta, materials });
  }

  /** The library's search, asked of the service (names and symbols first; never inside a citation). */
  async #search(query) {
    const answer = query.trim() ? await api.library(this.state.eta, query) : null;
    const ids = answer ? answer.materials.map((m) => m.id) : null;
    const suggested = answer ? (answer.suggestions || []).map((m) => m.id) : [];
    if ($("library-search").value === query) this.app.store.dispatch("librarySearch", { query, ids, suggested });
  }

  /** The search of the saved materials, asked of the service (GET /materials?kind=curves&q=, every page). */
  async #searchSaved(query) {
    const ids = query.trim() ? (await api.listAllMaterials({ kinds: ["curves"], q: query.trim() })).map((m) => m.id) : null;
    if ($("saved-search").value === query) this.app.store.dispatch("savedSearch", { query, ids });
  }

  /**
   * The saved edited materials and the bin, again. Only the latest call's
   * lists are shown: an earlier call answered later (its pages read before
   * a delete or restore it did not see) would show them as they were.
   */
  async refresh() {
    const asked = ++this.refreshes;
    const [saved, bin] = await Promise.all([api.listAllMaterials({ kinds: ["curves"] }),
                                            api.listAllMaterials({ kinds: ["curves"], deleted: true })]);
    if (asked !== this.refreshes) return;
    this.app.store.dispatch("materials", { saved, bin });
    const listed = this.state.versions;
    if (listed && !saved.some((m) => m.id === listed.material.id)) this.app.store.dispatch("versions", null);
    if ($("saved-search").value.trim()) this.#searchSaved($("saved-search").value);
  }

  #said(text, undo = null) {
    const box = $("manage-message");
    box.replaceChildren(text);
    box.classList.add("ok");
    if (undo) {
      const button = document.createElement("button");
      button.type = "button";
      button.className = "chip";
      button.textContent = "Undo";
      button.addEventListener("click", this.app.guard(undo));
      box.append(" ", button);
    }
  }

  /**
   * `work` once the actions asked before it are done (their lists shown and
   * said): a delete clicked while a restore is answered acts after it.
   */
  #inTurn(work) {
    const turn = this.turns.then(work);
    this.turns = turn.catch(() => {});
    return turn;
  }

  rename(m, name) {
    return this.#inTurn(() => this.#rename(m, name));
  }

  remove(m) {
    return this.#inTurn(() => this.#remove(m));
  }

  restore(m) {
    return this.#inTurn(() => this.#restore(m));
  }

  async #rename(m, name) {
    let renamed;
    try {
      renamed = await api.renameMaterial(m.id, name);
    } catch (error) {
      this.app.report(error, () => this.rename(m, name), "Not renamed: ");
      return this.manage.render(this.state);
    }
    const continuing = this.app.continuing.material;
    if (continuing && continuing.id === m.id) {
      continuing.name = renamed.name;
      $("name").value = renamed.name;
    }
    await Promise.all([this.refresh(), this.app.reloadPicker()]);
    this.#said(`Renamed “${m.name}” to “${renamed.name}” (its versions keep the names they were saved under).`);
  }

  async #remove(m) {
    try {
      await api.deleteMaterial(m.id);
    } catch (error) {
      return this.app.report(error, () => this.remove(m), "Not deleted: ");
    }
    await Promise.all([this.refresh(), this.app.reloadPicker()]);
    this.#said(`Moved “${m.name}” to the bin (nothing is erased).`, () => this.restore(m));
  }

  async #restore(m) {
    try {
      await api.restoreMaterial(m.id);
    } catch (error) {
      return this.app.report(error, () => this.restore(m), "Not restored: ");
    }
    await Promise.all([this.refresh(), this.app.reloadPicker()]);
    this.#said(`Restored “${m.name}”.`);
  }

  async versions(m) {
    const listed = await api.versions(m.id);
    this.app.store.dispatch("versions", { material: m, list: listed.versions, latest: listed.version });
  }

  async copyLink(fitId) {
    const link = linkTo(fitId, location.origin);
    $("share-link").value = link;
    $("share-link").select();
    const copied = navigator.clipboard ? navigator.clipboard.writeText(link).then(() => true, () => false)
      : Promise.resolve(false);
    const state = this.state;
    const isDraft = state.fit && state.fit.id === fitId && unsaved(state);
    if (isDraft && this.draftTtl === undefined) this.draftTtl = (await api.domain()).draft_ttl_s;
    // The service keeps the draft from now on for its time to live, and says until when.
    const draft = isDraft ? draftExpiry((await api.linkFit(fitId)).expires_at, this.draftTtl) : "";
    copied.then((ok) => this.#said((ok ? `Link copied: ${link}` : `Link (select and copy it): ${link}`) + draft));
  }

  /** Fit an uploaded n, k file (saved under the upload's name; listed under Uploads) and open it. */
  async upload(file) {
    const app = this.app;
    await app.busy("Fitting the uploaded n, k…", async () => {
      const fit = await api.uploadNK(file, $("upload-name").value.trim());
      await app.reloadPicker(`saved:${fit.material_id}`);
      app.picked(`saved:${fit.material_id}`);
      await app.setBase(fit);
      app.sayUpload(`Fitted “${fit.name}” from ${file.name}; saved under that name (listed under Uploads).`, true);
    });
  }

  /** Open a pack or an export (POST /fits/import): the fit it names with its edit, or a new fit of its model. */
  async importFile(file) {
    const fit = await this.app.busy("Reading the file…", () => api.importFile(file));
    await this.openFit(fit.id);
    await this.app.reloadPicker();
    $("open-message").textContent = `Opened “${fit.name}” from ${file.name}.`;
  }

  /** Open a link ({fit} or {material, version}, linkOf). */
  async openLink(link) {
    if (link.fit) return this.openFit(link.fit);
    const material = link.version ? null : await api.getMaterial(link.material);
    if (material && material.kind === "library") return this.app.open(`library:${material.id}`, false);
    const fit = link.version ? await api.version(link.material, link.version) : material.latest_fit;
    await this.openFit(fit.id);
    if (material && material.deleted_at) this.app.say(`“${material.name}” is in the bin: restore it, or save to take it out.`);
  }

  /** Reopen the stored fit `fitId` with its edit: its base, its curves as the edits, the material it continues. */
  async openFit(fitId) {
    const app = this.app;
    await app.busy("Opening the fit…", async () => {
      const edit = await api.fitEdit(fitId);
      const request = edit.request;
      if (!request || !request.base || !(request.base.fit || request.base.material)) {
        // A library or n, k fit, or curves with no base: it opens as a base of its own.
        return app.setBase(await api.getFit(edit.base && edit.base.fit ? edit.base.fit : fitId));
      }
      const [base, fit] = await Promise.all([
        request.base.fit ? api.getFit(request.base.fit) : api.fitLibrary(request.base.material, [1.0, 2.5]),
        api.getFit(fitId),
      ]);
      await app.setBase(base);
      const state = this.state;
      app.store.dispatch("reopened", { edits: editsOf(request.curves, state.theta), fitId });
      app.continuing.material = { id: edit.material_id, name: edit.name, version: edit.version };
      $("name").value = edit.name;
      app.picked(`saved:${edit.material_id}`);
      app.present(fit, await api.curves(fit.id, state.eta, SAMPLES), snapshot(state));
    });
  }

  /** Compare the fit on screen with `fit` (labelled `label`), or end compare mode (null). */
  compare(fit, label = "") {
    const store = this.app.store;
    if (!fit) store.dispatch("compareOff");
    else store.dispatch("compareWith", { fit, label });
    return this.app.previewView.compare(fit, label);
  }

  async #compareCurves() {
    const other = this.state.compare;
    if (!other) return;
    const eta = this.state.eta;
    const curves = await api.curves(other.fit.id, eta, SAMPLES);
    this.app.store.dispatch("compareCurves", { fitId: other.fit.id, eta, model: curves.model });
  }
}
