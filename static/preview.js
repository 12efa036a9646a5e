// The real-time preview: WebGL2 running preview_shaders/glsl/shader_ball.frag
// (the project's own GLSL, loaded by glsl.js) on a sphere with an orbiting
// camera. Split on screen into labelled bands: the coated-conductor model
// from its packed float16 halves, adjusted Lazanyi, and the spectral
// reference, which the service sends as a float texture over
// (cos theta, eta_i) (GET /api/v1/fits/{id}/reference-texture).
//
// Roughness and the clear coat: while every lobe is a mirror the program
// is shader_ball.frag as it stands; once a lobe is rough, its split-sum
// variant (splitsum.js: the LUT and the prefiltered environment fetched on
// first use, albedo tables integrated when the settings change). Frames
// wait for those textures (the last frame stays, and `status` says so).
//
// Model kinds (kinds.js, from GET /api/v1/domain): the model band draws the
// kind of the fit shown, each kind its own programs (shader_ball.frag with
// the kind's cf_preview_model.glsl, its float16 coefficients in 14 words),
// compiled when a fit of that kind first shows.

import * as api from "./api.js";
import { drawInto, floatTarget, fullscreenProgram, readTarget } from "./glpass.js";
import { defaultModelKind, modelKind, modelKindNamed, modelKindsKnown, setModelKinds } from "./kinds.js";
import { ENVIRONMENT_NAMES, SplitSum, UNIT, setMaterial } from "./splitsum.js";

export const PANEL = { model: 0, lazanyi: 1, reference: 2 };
export const OUTPUT = { display: 0, linear: 1, fresnel: 2, geometry: 3, baseLight: 4, coatLight: 5, coat: 6 };
export const ENVIRONMENT = Object.fromEntries(ENVIRONMENT_NAMES.map((name, i) => [name, i]));
const LABELS = ["Model", "Adjusted Lazanyi", "Spectral reference"];

// The float16 halves and the kinds' words live in kinds.js (re-exported:
// the three.js material and older callers import them from here).
export { halfBits, wordsFor } from "./kinds.js";

// ------------------------------------------------------------ renderer

/**
 * The orbit camera: eye on a sphere of radius `distance` around the unit
 * sphere (yaw about y, pitch above the equator), looking at the origin, y
 * up; right and up scaled by tan(fov / 2). In double precision here, once
 * per frame (GPU trigonometry can be coarse).
 */
export function orbitCamera([yaw, pitch, distance], fov) {
  const eye = [distance * Math.cos(pitch) * Math.sin(yaw), distance * Math.sin(pitch), distance * Math.cos(pitch) * Math.cos(yaw)];
  const forward = eye.map((v) => -v / distance);
  // right = forward x (0, 1, 0), normalised
  let right = [-forward[2], 0, forward[0]];
  const length = Math.hypot(...right);
  right = right.map((v) => v / length);
  const up = [
    right[1] * forward[2] - right[2] * forward[1],
    right[2] * forward[0] - right[0] * forward[2],
    right[0] * forward[1] - right[1] * forward[0],
  ];
  const focal = Math.tan(0.5 * fov);
  return { eye, forward, right: right.map((v) => v * focal), up: up.map((v) => v * focal) };
}

export class ShaderBall {
  /** Use `await ShaderBall.create(canvas, labels, status)`. */
  constructor(canvas, labels, status, gl, mirror) {
    this.canvas = canvas;
    this.labels = labels;
    this.status = status;
    this.gl = gl;
    // shader_ball.frag, every lobe a mirror, by model kind (kinds.js):
    // the program, or a promise while it compiles.
    const kind = modelKindNamed(defaultModelKind());
    this.mirrors = new Map([[kind.name, mirror]]);
    this.mirror = mirror; // the default kind's
    this.vao = gl.createVertexArray();
    this.splitSum = new SplitSum(gl, this.vao);
    this.lightingError = null;
    this.state = {
      orbit: [0.5, 0.25, 4.2], fov: 0.52, panels: [PANEL.model], caption: "", environment: ENVIRONMENT.studio,
      exposure: 0, eta: 1.5, words: new Uint32Array(14), etaRange: [1, 2.5],
      F0: [0, 0, 0], F82: [0, 0, 0], fitId: null, referenceFor: null, referenceRange: [1, 2.5],
      model: kind.name, kind,
      roughness: 0, coated: false, coatRoughness: 0,
    };
    this.reference = this.#texture(new Float32Array(6), 2, 1);
    this.frames = 0;
    this.pending = false;
    this.onFrame = null;
    this.#bindOrbit();
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  static async create(canvas, labels, status = null) {
    const gl = canvas.getContext("webgl2", { antialias: false, preserveDrawingBuffer: true });
    if (!gl) throw new Error("this browser has no WebGL2");
    if (!modelKindsKnown()) setModelKinds(await api.domain());
    const kind = modelKindNamed(defaultModelKind());
    return new ShaderBall(canvas, labels, status, gl, await fullscreenProgram(gl, "shader_ball.frag", {}, kind.sources));
  }

  #texture(data, width, height) {
    const gl = this.gl;
    const texture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB32F, width, height, 0, gl.RGB, gl.FLOAT, data);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T]) gl.texParameteri(gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE);
    return texture;
  }

  /**
   * The fit to show (its FitPublic answer): words, domain; drawn at once,
   * not on the next animation frame (a refit's frame follows its curve
   * without waiting up to a display interval; orbiting still coalesces).
   */
  setFit(fit) {
    const kind = modelKind(fit);
    Object.assign(this.state, {
      words: kind.words(fit.coefficients), etaRange: fit.eta_i_range, fitId: fit.id, model: kind.name, kind,
    });
    this.drawNow();
  }

  /** A promise of the mirror program of model kind `kind` (kinds.js; compiled once). */
  #mirrorFor(kind) {
    const made = this.mirrors.get(kind.name);
    if (made && !(made instanceof Promise)) return Promise.resolve(made);
    if (!made) {
      const compiling = fullscreenProgram(this.gl, "shader_ball.frag", {}, kind.sources).then((program) => {
        this.mirrors.set(kind.name, program);
        return program;
      }, (error) => {
        this.mirrors.delete(kind.name);
        this.#say(`The preview cannot draw this kind: ${error.message}`);
        throw error;
      });
      this.mirrors.set(kind.name, compiling);
    }
    return this.mirrors.get(kind.name);
  }

  /**
   * A promise resolved once the current settings can be drawn: the fit's
   * kind's programs, and for a rough lobe the split sum's textures.
   */
  ready() {
    return this.#mirrorFor(this.state.kind).then(() => this.lightingReady()).then(() => this.draw());
  }

  /** The spectral reference texture and Lazanyi inputs (see api.referenceTexture). */
  setReference(texture) {
    const gl = this.gl;
    gl.deleteTexture(this.reference);
    this.reference = this.#texture(texture.data, texture.width, texture.height);
    Object.assign(this.state, {
      F0: texture.F0_air, F82: texture.F82_air, referenceRange: texture.eta_i_range, referenceFor: texture.fitId,
    });
    this.draw();
  }

  /**
   * Change settings ({eta, environment, exposure, panels, orbit, roughness
   * in [0, 1], coated, coatRoughness in [0, 1]}) and draw.
   */
  set(changes) {
    Object.assign(this.state, changes);
    this.draw();
  }

  // ---------------------------------------------------------- split sum

  /** Whether a lobe is rough (the split sum), unless its textures are out of reach. */
  #rough() {
    const s = this.state;
    return !this.lightingError && (s.roughness > 0 || (s.coated && s.coatRoughness > 0));
  }

  /**
   * A promise of the split sum's textures and programs for the current
   * settings, each fetched or compiled once; resolved at once while every
   * lobe is a mirror. A failure is reported in `status`, and the preview
   * then draws every lobe as a mirror.
   */
  lightingReady() {
    if (!this.#rough()) return this.#mirrorFor(this.state.kind).then(() => this.draw());
    return this.splitSum.load(this.state.environment, this.state.kind).then(() => this.draw(), (error) => {
      this.lightingError = error;
      this.#say(`Rough lighting unavailable, every surface is drawn smooth: ${error.message}`);
      this.draw();
    });
  }

  #say(text) {
    if (!this.status) return;
    this.status.textContent = text;
    this.status.hidden = !text;
  }

  // The program of this frame, its albedo tables integrated; null while
  // the split sum's textures are on their way.
  #program() {
    const s = this.state;
    if (!this.#rough()) {
      const mirror = this.mirrors.get(s.kind.name);
      if (!mirror || mirror instanceof Promise) {
        this.#mirrorFor(s.kind).then(() => this.draw(), () => {});
        return null;
      }
      if (!this.lightingError) this.#say("");
      return mirror;
    }
    if (!this.splitSum.loaded(s.environment, s.kind)) {
      this.#say("Preparing the rough lighting…");
      this.lightingReady();
      return null;
    }
    this.#say("");
    this.splitSum.integrate(s, this.reference, s.panels.includes(PANEL.reference));
    return this.splitSum.programFor(s.kind);
  }

  /** The split sum's albedo tables as last integrated, for the parity tests. */
  readTables() {
    return this.splitSum.readTables();
  }

  #uniforms(ball, output, width, height) {
    const gl = this.gl, u = ball.uniforms, s = this.state;
    gl.useProgram(ball.program);
    gl.uniform2f(u.u_resolution, width, height);
    const camera = orbitCamera(s.orbit, s.fov);
    for (const name of ["eye", "forward", "right", "up"]) gl.uniform3f(u[`u_${name}`], ...camera[name]);
    const kinds = [...s.panels, PANEL.model, PANEL.model].slice(0, 3);
    gl.uniform1i(u.u_panels, s.panels.length);
    gl.uniform3i(u.u_panel_kind, ...kinds);
    gl.uniform1i(u.u_environment, s.environment);
    gl.uniform1f(u.u_exposure, s.exposure);
    gl.uniform1i(u.u_output, output);
    setMaterial(gl, u, s);
    gl.activeTexture(gl.TEXTURE0 + UNIT.reference);
    gl.bindTexture(gl.TEXTURE_2D, this.reference);
    gl.uniform1i(u.u_reference, UNIT.reference);
    if (ball === this.splitSum.programFor(s.kind)) this.splitSum.bind(u, s.environment);
  }

  /** Ask for a frame (drawn on the next animation frame, once). */
  draw() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.drawNow();
    });
  }

  /** Draw the canvas now; the canvas's data-fit names the fit drawn. */
  drawNow() {
    const ball = this.#program();
    if (!ball) return;
    const gl = this.gl, canvas = this.canvas;
    // Half resolution while a handle is held (state.held), as viewports do while dragging.
    const scale = Math.min(window.devicePixelRatio || 1, 2) * (this.state.held ? 0.5 : 1);
    const width = Math.max(1, Math.round(canvas.clientWidth * scale));
    const height = Math.max(1, Math.round(canvas.clientHeight * scale));
    if (canvas.width !== width || canvas.height !== height) {
      canvas.width = width;
      canvas.height = height;
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, width, height);
    this.#uniforms(ball, OUTPUT.display, width, height);
    gl.bindVertexArray(this.vao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    this.frames += 1;
    canvas.dataset.fit = this.state.fitId || "";
    canvas.dataset.eta = this.state.eta.toFixed(2);
    canvas.dataset.program = ball === this.splitSum.programFor(this.state.kind) ? "split-sum" : "mirror";
    canvas.dataset.model = this.state.model;
    this.#label();
    if (this.onFrame) this.onFrame(this.state);
  }

  #label() {
    if (!this.labels) return;
    // A caption (compare mode: which fit this ball is) leads the label of a ball of one panel.
    const { panels, caption } = this.state;
    const text = (kind) => (caption && panels.length === 1 ? `${caption}: ${LABELS[kind]}` : LABELS[kind]);
    const wanted = panels.map(text).join("|");
    if (this.labels.dataset.panels === wanted) return;
    this.labels.dataset.panels = wanted;
    this.labels.replaceChildren(...panels.map((kind) => {
      const span = document.createElement("span");
      span.textContent = text(kind);
      return span;
    }));
  }

  /**
   * Render `output` (OUTPUT.*) at width x height into an RGBA32F target
   * (EXT_color_buffer_float) and read it back: (height x width x 4) floats,
   * bottom row first, as GL stores it. For the parity tests.
   */
  readFloat(output, width, height) {
    const ball = this.#program();
    if (!ball) throw new Error("the programs or the split sum's textures are not in yet: await ready()");
    const gl = this.gl;
    const target = floatTarget(gl, width, height);
    this.#uniforms(ball, output, width, height);
    drawInto(gl, this.vao, [target], width, height);
    const pixels = readTarget(gl, target, width, height);
    gl.deleteTexture(target);
    return pixels;
  }

  #bindOrbit() {
    const canvas = this.canvas;
    let last = null;
    canvas.addEventListener("pointerdown", (event) => {
      canvas.setPointerCapture(event.pointerId);
      last = [event.clientX, event.clientY];
    });
    canvas.addEventListener("pointermove", (event) => {
      if (!last) return;
      const [yaw, pitch, distance] = this.state.orbit;
      const dx = event.clientX - last[0], dy = event.clientY - last[1];
      last = [event.clientX, event.clientY];
      this.set({ orbit: [yaw - dx * 0.01, Math.max(-1.45, Math.min(1.45, pitch + dy * 0.01)), distance] });
    });
    const release = () => { last = null; };
    canvas.addEventListener("pointerup", release);
    canvas.addEventListener("pointercancel", release);
    canvas.addEventListener("wheel", (event) => {
      event.preventDefault();
      const [yaw, pitch, distance] = this.state.orbit;
      this.set({ orbit: [yaw, pitch, Math.max(1.6, Math.min(10, distance * Math.exp(event.deltaY * 0.001)))] });
    }, { passive: false });
  }
}
