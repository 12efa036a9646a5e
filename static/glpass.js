// Small WebGL2 helpers of the preview's passes: a program from the
// project's GLSL, float targets, a full-screen pass into them and their
// read-back (EXT_color_buffer_float), for the preview, its albedo table
// and the parity tests.

import { loadShader } from "./glsl.js";

function compile(gl, type, source, name) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
    throw new Error(`${name} does not compile as GLSL ES 3.00: ${gl.getShaderInfoLog(shader)}`);
  }
  return shader;
}

/**
 * The program of `fullscreen.vert` and the fragment shader `name` (a
 * preview_shaders/glsl file; `defines` become `#define` lines after the
 * version line; `sources`: generated includes by name, kinds.js's
 * previewSources), with its uniforms' locations by name.
 */
export async function fullscreenProgram(gl, name, defines = {}, sources = {}) {
  const [vertex, fragment] = await Promise.all([loadShader("fullscreen.vert"), loadShader(name, "/glsl", sources)]);
  const lines = Object.entries(defines).map(([key, value]) => `#define ${key} ${value}`);
  const newline = fragment.indexOf("\n");
  const source = lines.length ? `${fragment.slice(0, newline)}\n${lines.join("\n")}${fragment.slice(newline)}` : fragment;
  const program = gl.createProgram();
  gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, vertex, "fullscreen.vert"));
  gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, source, name));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) {
    throw new Error(`${name} does not link: ${gl.getProgramInfoLog(program)}`);
  }
  const uniforms = {};
  const count = gl.getProgramParameter(program, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < count; i++) {
    const uniform = gl.getActiveUniform(program, i).name.replace(/\[0\]$/, "");
    uniforms[uniform] = gl.getUniformLocation(program, uniform);
  }
  return { program, uniforms };
}

/** An RGBA32F texture to render into (EXT_color_buffer_float), sampled with texelFetch. */
export function floatTarget(gl, width, height) {
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("this browser cannot render float targets (EXT_color_buffer_float)");
  const texture = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, texture);
  gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, width, height);
  for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
  return texture;
}

/**
 * Draw the full-screen triangle of the program in use (its uniforms set)
 * into `targets` (float textures of width x height, one per output of the
 * fragment shader, in location order).
 */
export function drawInto(gl, vao, targets, width, height) {
  const fbo = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
  targets.forEach((texture, i) => gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, texture, 0));
  gl.drawBuffers(targets.map((_, i) => gl.COLOR_ATTACHMENT0 + i));
  gl.viewport(0, 0, width, height);
  gl.bindVertexArray(vao);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.deleteFramebuffer(fbo);
}

/** A float target's texels, (height x width x 4) floats, bottom row first, as GL stores them. */
export function readTarget(gl, texture, width, height) {
  const fbo = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
  gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, texture, 0);
  const pixels = new Float32Array(width * height * 4);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.FLOAT, pixels);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.deleteFramebuffer(fbo);
  return pixels;
}
