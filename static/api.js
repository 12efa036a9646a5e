// Calls to the service's HTTP API (same origin). A refusal becomes an Error
// whose message is the service's `detail` (it names the field and the rule)
// and whose `status` is the HTTP status (401: the API token is missing or wrong).

const API = "/api/v1";
const TOKEN_KEY = "coated-api-token";

// The bearer token of the write endpoints (COATED_API_TOKEN), kept for this
// tab only; sent with every request once set.
export function getToken() {
  try {
    return sessionStorage.getItem(TOKEN_KEY) || "";
  } catch (_) {
    return ""; // storage disabled: no token
  }
}

export function setToken(token) {
  if (token) sessionStorage.setItem(TOKEN_KEY, token);
  else sessionStorage.removeItem(TOKEN_KEY);
}

function headers(extra = {}) {
  const token = getToken();
  return token ? { ...extra, Authorization: `Bearer ${token}` } : extra;
}

async function answer(response, read = (r) => r.json()) {
  if (response.ok) return read(response);
  let detail = `${response.status} ${response.statusText}`;
  try {
    const body = await response.json();
    if (body && body.detail) detail = body.detail;
  } catch (_) {
    // Not JSON (a proxy's page): the status line is all there is.
  }
  const error = new Error(detail);
  error.status = response.status;
  const retryAfter = Number(response.headers.get("Retry-After"));
  error.retryAfter = Number.isFinite(retryAfter) && retryAfter > 0 ? Math.min(retryAfter, 10) : null;
  throw error;
}

export async function getJSON(path) {
  return answer(await fetch(API + path, { headers: headers({ Accept: "application/json" }) }));
}

export async function postJSON(path, body, signal = undefined) {
  return answer(await fetch(API + path, {
    method: "POST",
    headers: headers({ "Content-Type": "application/json", Accept: "application/json" }),
    body: JSON.stringify(body),
    signal,
  }));
}

export async function postForm(path, form) {
  return answer(await fetch(API + path, { method: "POST", headers: headers(), body: form }));
}

// One page of materials. kinds: "library", "curves" (saved edits), "nk" (uploads); the service's
// default is library and curves. q: only names, symbols or sources holding it (the service's rule).
export function listMaterials({ kinds = null, deleted = false, q = null, cursor = null } = {}) {
  const query = new URLSearchParams();
  for (const kind of kinds || []) query.append("kind", kind);
  if (deleted) query.set("deleted", "true");
  if (q) query.set("q", q);
  if (cursor !== null && cursor !== undefined) query.set("cursor", String(cursor));
  const text = query.toString();
  return getJSON(`/materials${text ? `?${text}` : ""}`);
}

/** Every material listMaterials selects: its pages one after another, following next_cursor. */
export async function listAllMaterials(options = {}) {
  const all = [];
  let cursor = null;
  do {
    const page = await listMaterials({ ...options, cursor });
    all.push(...page.materials);
    cursor = page.next_cursor ?? null;
  } while (cursor !== null);
  return all;
}
export const getMaterial = (id) => getJSON(`/materials/${encodeURIComponent(id)}`);
export const getFit = (id) => getJSON(`/fits/${encodeURIComponent(id)}`);
export const fitEdit = (id) => getJSON(`/fits/${encodeURIComponent(id)}/edit`);
export const versions = (id) => getJSON(`/materials/${encodeURIComponent(id)}/versions?limit=50`);
export const version = (id, n) => getJSON(`/materials/${encodeURIComponent(id)}/versions/${Number(n)}`);
// The library's conductors at a coat index; with `q` those matching it, best first (the service ranks them).
export const library = (etaI, q = null) =>
  getJSON(`/library?eta_i=${etaI.toFixed(2)}${q ? `&q=${encodeURIComponent(q)}` : ""}`);
export const coatPresets = () => getJSON("/coat-presets");
let domainAnswer = null;
/** GET /domain, asked once a page (its rules and registries do not change while a server runs; a failure is asked again). */
export function domain() {
  if (!domainAnswer) domainAnswer = getJSON("/domain").catch((error) => { domainAnswer = null; throw error; });
  return domainAnswer;
}

async function send(method, path, body = null) {
  const init = { method, headers: headers({ Accept: "application/json" }) };
  if (body !== null) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  return answer(await fetch(API + path, init));
}

// The writes on a saved material (each with the token when one is set: send() adds it).
export const renameMaterial = (id, name) => send("PATCH", `/materials/${encodeURIComponent(id)}`, { name });
export const deleteMaterial = (id) => send("DELETE", `/materials/${encodeURIComponent(id)}`);
export const restoreMaterial = (id) => send("POST", `/materials/${encodeURIComponent(id)}/restore`);
// A link to a fit: a draft is then kept the drafts' time to live from now ({expires_at}).
export const linkFit = (fitId) => send("POST", `/fits/${encodeURIComponent(fitId)}/link`);
// `?metrics=full`: the editor shows the fit's figure, so its answer waits for the evaluation on the
// metrics grid (without it an n, k fit answers as soon as it is saved, `metrics.evaluated` false).
export const fitLibrary = (name, etaRange) =>
  postJSON("/fits?metrics=full", { material: name, eta_i_range: etaRange });
// With `curvesAt` ({ etaI, samples }), the answer also holds the fit's curves
// there (`curves`, as curves() gives): one round trip per refit.
// `signal` (an AbortSignal) aborts the request: the service then cancels its job.
export function fitFromCurves(body, curvesAt = null, signal = undefined) {
  const query = curvesAt ? `?curves_eta_i=${curvesAt.etaI.toFixed(3)}&curves_samples=${curvesAt.samples}` : "";
  return postJSON(`/fits/from-curves${query}`, body, signal);
}
// The curves (linear ACEScg) of the metal of a base colour and an edge tint (nothing stored).
export const colourCurves = (body) => postJSON("/colour-curves", body);
export const errorMap = (fitId) => getJSON(`/fits/${fitId}/error-map?angles=46&rows=31`);

export function uploadNK(file, name = "") {
  const form = new FormData();
  form.append("file", file, file.name);
  if (name) form.append("name", name);
  return postForm("/fits/upload?metrics=full", form);
}

// A pack or an export of this service read back to its fit (the stored fit it names, or a new one of its model).
export function importFile(file) {
  const form = new FormData();
  form.append("file", file, file.name);
  return postForm("/fits/import", form);
}

export function curves(fitId, etaI, samples) {
  return getJSON(`/fits/${fitId}/curves?eta_i=${etaI.toFixed(3)}&samples=${samples}`);
}

// The preview sphere as a PNG blob.
export async function preview(fitId, etaI, compare) {
  const path = `/preview.png?fit=${fitId}&eta_i=${etaI.toFixed(3)}&size=320&compare=${compare}`;
  return answer(await fetch(API + path, { headers: headers() }), (r) => r.blob());
}

// EXPORTS take the preview's settings (eta_i, roughness, coat roughness); the packs hold every eta_i.
// The names are the service's registry (GET /domain's export_formats), filled by setExportFormats.
export const EXPORTS = new Set();

/** Take the export formats of GET /domain ([{name, label, ...}]) as the ones packURL knows. */
export function setExportFormats(formats) {
  EXPORTS.clear();
  for (const format of formats) EXPORTS.add(format.name);
}

/** The download of a fit in `format`; an export at `settings` {etaI, roughness, coatRoughness}. */
export function packURL(fitId, format, settings = null) {
  const url = `${API}/fits/${fitId}/pack?format=${format}`;
  if (!settings || !EXPORTS.has(format)) return url;
  const { etaI, roughness, coatRoughness } = settings;
  return `${url}&eta_i=${etaI.toFixed(2)}&roughness=${roughness.toFixed(2)}&coat_roughness=${coatRoughness.toFixed(2)}`;
}

// The spectral reference of a fit with n, k as a float texture over
// (cos theta, eta_i) (GET /fits/{id}/reference-texture): float32 RGB,
// [eta_i row][cos theta column][channel], sizes and ranges in the headers.
export async function referenceTexture(fitId) {
  const response = await fetch(`${API}/fits/${fitId}/reference-texture`, { headers: headers() });
  const buffer = await answer(response, (r) => r.arrayBuffer());
  const triple = (name) => response.headers.get(name).split(",").map(Number);
  return {
    fitId,
    data: new Float32Array(buffer),
    width: Number(response.headers.get("X-Texture-Width")),
    height: Number(response.headers.get("X-Texture-Height")),
    eta_i_range: triple("X-Eta-I-Range"),
    F0_air: triple("X-F0-Air"),
    F82_air: triple("X-F82-Air"),
  };
}

// ---------------------------------------------------------------- split sum

const LUT_MAGIC = "CFIBLUT1";
const LUT_HEADER_BYTES = 32;

let crcTable = null;

// CRC-32 (zlib's, reflected 0xEDB88320) of a byte array.
function crc32(bytes) {
  if (!crcTable) {
    crcTable = new Uint32Array(256);
    for (let n = 0; n < 256; n++) {
      let c = n;
      for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
      crcTable[n] = c >>> 0;
    }
  }
  let crc = 0xffffffff;
  for (let i = 0; i < bytes.length; i++) crc = crcTable[(crc ^ bytes[i]) & 0xff] ^ (crc >>> 8);
  return (crc ^ 0xffffffff) >>> 0;
}

/**
 * The split-sum LUT file (docs/shading.md: magic CFIBLUT1, uint32 n_mu,
 * n_r, n_alpha, channels, float32 alpha range, float32 (A, B, G) texels
 * [alpha slice][roughness][NdotV][channel], CRC-32), read as
 * fitting.shading.lut.decode_lut does; a damaged file is refused with why.
 */
export function decodeLut(buffer) {
  const view = new DataView(buffer);
  if (buffer.byteLength < LUT_HEADER_BYTES + 4) throw new Error(`the LUT is truncated: ${buffer.byteLength} bytes`);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 8));
  if (magic !== LUT_MAGIC) throw new Error(`not a split-sum LUT (magic ${JSON.stringify(magic)})`);
  const [width, height, depth, channels] = [8, 12, 16, 20].map((offset) => view.getUint32(offset, true));
  const alphaRange = [view.getFloat32(24, true), view.getFloat32(28, true)];
  const size = LUT_HEADER_BYTES + 4 * channels * width * height * depth;
  if (channels !== 3 || buffer.byteLength !== size + 4) {
    throw new Error(`the LUT header (${width} x ${height} x ${depth} x ${channels}) does not match its ${buffer.byteLength} bytes`);
  }
  if (crc32(new Uint8Array(buffer, 0, size)) !== view.getUint32(size, true)) throw new Error("the LUT is damaged: CRC-32 mismatch");
  // The texels are little-endian, as typed arrays are on every WebGL platform.
  return { width, height, depth, alphaRange, data: new Float32Array(buffer.slice(LUT_HEADER_BYTES, size)) };
}

// GET /ibl-lut, decoded.
export async function iblLut() {
  const response = await fetch(`${API}/ibl-lut`, { headers: headers() });
  return decodeLut(await answer(response, (r) => r.arrayBuffer()));
}

// A preview environment prefiltered per roughness (GET
// /environments/{name}/prefiltered): float32 RGB [slice][row][column][channel].
export async function prefilteredEnvironment(name) {
  const response = await fetch(`${API}/environments/${encodeURIComponent(name)}/prefiltered`, { headers: headers() });
  const buffer = await answer(response, (r) => r.arrayBuffer());
  const [width, height, layers] = ["Width", "Height", "Layers"].map((k) => Number(response.headers.get(`X-Texture-${k}`)));
  if (buffer.byteLength !== 12 * width * height * layers) {
    throw new Error(`the prefiltered ${name} environment has ${buffer.byteLength} bytes for ${width} x ${height} x ${layers}`);
  }
  return { name, width, height, layers, data: new Float32Array(buffer) };
}
