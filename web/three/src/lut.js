// The split-sum LUT the material's albedo tables read (docs/shading.md),
// decoded from the package's generated/lut.js at first use: no three.js,
// no DOM; DecompressionStream ("deflate", zlib) inflates it, which every
// browser with WebGL2 and Node 18+ have.

import { LUT } from "./generated/lut.js";

/**
 * The split-sum LUT (what GET /api/v1/ibl-lut serves, docs/shading.md) as
 * float32 texels, width x height x depth x (A, B, G): inflated from the
 * package's generated/lut.js (A and B once, then G, in byte planes).
 */
export async function lutTexels() {
  const { width, height, depth, deflated } = LUT;
  const binary = atob(deflated);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
  const planes = new Uint8Array(await new Response(stream).arrayBuffer());
  const count = planes.length / 4;
  if (count !== (2 + depth) * width * height) {
    throw new Error(`the LUT has ${count} values for ${width} x ${height} x ${depth}`);
  }
  const values = new Uint8Array(4 * count);
  for (let b = 0; b < 4; b++) {
    const plane = planes.subarray(b * count, (b + 1) * count);
    for (let i = 0; i < count; i++) values[4 * i + b] = plane[i];
  }
  const floats = new Float32Array(values.buffer); // little-endian, as typed arrays are on every WebGL platform
  const texels = new Float32Array(3 * width * height * depth);
  const slice = width * height;
  for (let k = 0; k < depth; k++) {
    for (let t = 0; t < slice; t++) {
      const o = 3 * (k * slice + t);
      texels[o] = floats[2 * t];
      texels[o + 1] = floats[2 * t + 1];
      texels[o + 2] = floats[2 * slice + k * slice + t];
    }
  }
  return { width, height, depth, alphaRange: LUT.alphaRange.slice(), data: texels };
}
