// Loads the project's own GLSL (preview_shaders/glsl/, served at /glsl/) as
// GLSL ES 3.00 for WebGL2: the files are shared with the Python renderer
// (moderngl, GLSL 4.30), never copied. A main shader's `#version` line is
// replaced by `#version 300 es` and precision statements; `#include "f"`
// lines are replaced by the file, each file once (its include guard covers
// repeats), as preview_shaders.gl.load_shader_source does. `sources` gives
// the text of generated includes by name: the preview's
// cf_preview_model.glsl of a model kind, served by GET /api/v1/domain
// (kinds.js).

const INCLUDE = /^\s*#include\s+"([^"]+)"\s*$/gm;
const ES_HEADER = [
  "#version 300 es",
  "precision highp float;",
  "precision highp int;",
  "precision highp sampler2D;",
].join("\n");

const files = new Map(); // name -> Promise<string>

function fetchFile(base, name) {
  if (!/^[A-Za-z0-9_.-]+$/.test(name)) throw new Error(`not a shader file name: ${name}`);
  if (!files.has(name)) {
    files.set(name, fetch(`${base}/${name}`).then((r) => {
      if (!r.ok) throw new Error(`shader ${name}: ${r.status} ${r.statusText}`);
      return r.text();
    }));
  }
  return files.get(name);
}

// Every file `name` includes, fetched in parallel level by level.
async function expand(base, name, seen, sources = {}) {
  if (seen.has(name)) return "";
  seen.add(name);
  const text = Object.hasOwn(sources, name) ? sources[name] : await fetchFile(base, name);
  const names = [...text.matchAll(INCLUDE)].map((m) => m[1]);
  const bodies = new Map();
  for (const included of names) bodies.set(included, await expand(base, included, seen, sources));
  return text.replace(INCLUDE, (_, included) => bodies.get(included) ?? "");
}

/** The GLSL ES 3.00 source of `name` with its includes resolved (`sources`: generated includes by name). */
export async function loadShader(name, base = "/glsl", sources = {}) {
  const source = await expand(base, name, new Set(), sources);
  const newline = source.indexOf("\n");
  const head = source.slice(0, newline);
  if (!head.startsWith("#version")) throw new Error(`${name} must start with a #version line`);
  return `${ES_HEADER}\n${source.slice(newline + 1)}`;
}

/**
 * The include files `names` (no #version line), each with its includes
 * resolved, concatenated in order, every file once: GLSL to paste into
 * another program's source (the three.js example page draws its
 * environments with it; the three.js package, web/three/, carries its own
 * copy, written by `python -m preview_shaders.three_package`).
 */
export async function loadIncludes(names, base = "/glsl") {
  const seen = new Set();
  const parts = [];
  for (const name of names) parts.push(await expand(base, name, seen));
  return parts.join("\n");
}

/** Fetch the files of `names` (and what they include) ahead of use. */
export function prefetch(names, base = "/glsl") {
  for (const name of names) fetchFile(base, name).catch(() => {});
}
