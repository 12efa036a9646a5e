// What the editor says: the message line, the upload's message, the busy
// spinner, "updating…" while the fit on screen lags the edits, and the API
// token (a 401 opens its field; the refused action is retried once a token
// is entered). A view of no state: the editor calls it.

import * as api from "../api.js";

const $ = (id) => document.getElementById(id);

export class Messages {
  constructor() {
    this.retryAfterToken = null;
    this.busyCount = 0;
    $("token").value = api.getToken();
    $("token-form").addEventListener("submit", (event) => {
      event.preventDefault();
      api.setToken($("token").value.trim());
      this.say(api.getToken() ? "API token set for this tab." : "API token cleared.", true);
      const retry = this.retryAfterToken;
      this.retryAfterToken = null;
      if (retry) this.guard(retry)();
    });
  }

  /** The message line; `kind` tags a message so that what resolves it clears it ("retry": the next answer). */
  say(text, ok = false, kind = "") {
    const box = $("message");
    box.textContent = text;
    box.classList.toggle("ok", ok);
    box.dataset.kind = text ? kind : "";
  }

  /** Clear the message if it is of `kind`. */
  clear(kind) {
    if ($("message").dataset.kind === kind) this.say("");
  }

  sayUpload(text, ok = false) {
    const box = $("upload-message");
    box.textContent = text;
    box.classList.toggle("ok", ok);
  }

  /**
   * A refusal, shown; a 401 (the service wants its API token) opens the
   * token field and remembers `retry`, run again once a token is entered.
   */
  report(error, retry = null, prefix = "") {
    if (error.status !== 401) {
      this.say(prefix + error.message);
      return;
    }
    this.retryAfterToken = retry;
    $("token-settings").open = true;
    $("token").focus();
    this.say(`${prefix}The service needs its API token (401). Enter it under “API token” ` +
      `and press Use token${retry ? "; the action is then retried" : ""}.`);
  }

  /** `work` with its refusals reported (and retried after a token, for a 401). */
  guard(work) {
    const run = (...args) => Promise.resolve(work(...args)).catch((error) => this.report(error, () => run(...args)));
    return run;
  }

  /** The spinner with `text` while `work` runs (nested calls share it). */
  async busy(text, work) {
    this.busyCount += 1;
    $("busy-text").textContent = text;
    $("busy").hidden = false;
    document.body.setAttribute("aria-busy", "true");
    try {
      return await work();
    } finally {
      this.busyCount -= 1;
      if (this.busyCount === 0) {
        $("busy").hidden = true;
        document.body.removeAttribute("aria-busy");
      }
    }
  }

  /** "updating…" on the preview and plot while the fit on screen is not the fit of the edits on screen. */
  updating(on) {
    $("preview-state").hidden = !on;
    document.querySelector(".side").classList.toggle("updating", on);
    $("plot").classList.toggle("updating", on);
  }
}
