// Saving the edit (POST /fits/from-curves, draft false), as a material an
// artist keeps saving: the saved material this edit continues (the one
// opened from the list, or the one this page saved it as) gets the next
// version under its id (material_id, expected_version: a save from
// elsewhere since is a 409, nothing lost), with no "Replace it?" question;
// a name that belongs to another saved material asks first; a save of the
// material as it was saved answers "nothing to save" (no new version).
//
// `ctx`: state, name() -> the name field, say(text, ok), report(error,
// retry, prefix), busy(text, work), refitFirst() -> Promise<bool> (the fit
// on screen is the fit of the edits), failed() -> the pipeline's refusal,
// refresh(value) -> the material list again, `value` chosen, onSaved(fit, edited) -> Promise
// (`edited`: the snapshot of the edits saved).

import * as api from "../api.js";
import { refitBody } from "./refit.js";
import { fitted, snapshot, unsaved } from "./state.js";

/** The saved material an edit continues: {id, name, version} (version: saves so far when last read). */
export class Continuing {
  constructor() {
    this.material = null;
  }

  /** The base opened: a saved edited material continues itself (its version read from its detail). */
  opened(fit, version = null) {
    this.material = fit.kind === "curves" ? { id: fit.material_id, name: fit.name, version } : null;
  }

  /** Whether a save under `name` continues the material (its name unchanged). */
  continues(name) {
    return this.material !== null && this.material.name === name;
  }
}

export async function save(ctx, continuing) {
  const name = ctx.name().trim();
  const state = ctx.state;
  if (!name) {
    ctx.say("Give the material a name first.");
    return false;
  }
  if (!Object.keys(state.edits).length) {
    ctx.say("Nothing to save: edit a curve first.");
    return false;
  }
  const going = continuing.continues(name);
  if (going && !unsaved(state) && fitted(state)) {
    // The material's latest version is what is on screen: another save would only repeat it.
    const version = continuing.material.version;
    ctx.say(`Nothing to save: “${name}”${version ? ` version ${version}` : ""} is what is on screen.`, true);
    return false;
  }
  if (!going) {
    // Saving under the name of another saved material replaces its latest fit: asked first.
    // The service is asked (every page of the saved materials holding the name), not the list on screen.
    const materials = await api.listAllMaterials({ kinds: ["curves"], q: name });
    const clash = materials.find((m) => m.name === name);
    if (clash && !window.confirm(`A saved material is called “${name}”. Replace it with this edit?`)) {
      ctx.say("Not saved: choose another name, or Save again and confirm to replace it.");
      return false;
    }
  }
  // A refused refit (401, 422) is reported by the pipeline: nothing was saved.
  if (!(await ctx.refitFirst())) {
    if (ctx.failed()) ctx.say(`Not saved: ${ctx.failed().message}`);
    return false;
  }
  const edited = snapshot(state);
  const body = refitBody({ name, base: state.base, theta: state.theta, edits: state.edits, draft: false });
  if (going) {
    body.material_id = continuing.material.id;
    if (continuing.material.version !== null) body.expected_version = continuing.material.version;
  }
  let fit;
  try {
    fit = await ctx.busy("Saving…", () => api.fitFromCurves(body));
  } catch (error) {
    if (error.status === 409 && going) {
      ctx.say(`Not saved: ${error.message} Open the material again to continue from its latest version.`);
    } else {
      ctx.report(error, () => save(ctx, continuing), "Not saved: ");
    }
    return false;
  }
  const materials = await ctx.refresh(`saved:${fit.material_id}`);
  const entry = materials.find((m) => m.id === fit.material_id);
  continuing.material = { id: fit.material_id, name: fit.name, version: entry ? entry.version : null };
  await ctx.onSaved(fit, edited);
  ctx.say((going
    ? `Saved “${fit.name}”, version ${entry ? entry.version : "?"}: it continues the material (its history is kept).`
    : `Saved “${fit.name}”: it is in the material list (Saved) and survives restarts.`)
    + (fit.restored_from_bin ? " It was in the bin: this save took it out." : ""), true);
  return true;
}
