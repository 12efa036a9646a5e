// The escape table of a coated metal in three.js: what the metal's rough
// lobe sends back into the coat (fitting/shading/coated_layer.py is the
// numpy twin and says why). Drawn by three into an n x 2 float target when
// the material's roughness (or the model) changes:
//   row 0, node i (in-coat cosine (i / (n - 1))^2, as the albedo table):
//     q, the share of the lobe's energy that leaves through the coat's
//     underside at once (the coat's transmission at each direction, 0
//     beyond the critical angle), by ESCAPE_SAMPLES visible normals;
//   row 1: E_bar, the lobe's hemispherical albedo (16 cosines, midpoints
//     in cos^2, HEMISPHERE_SAMPLES visible normals each), in every texel.
// The coat's hemispherical reflectance from inside, r_bar, is the same for
// every material of a coat index: internalReflectance(eta) computes it.

import * as THREE from "three";
import { drawInto } from "./albedo_table.js";

export const ESCAPE_SAMPLES = 256;
export const HEMISPHERE_SAMPLES = 64;
export const HEMISPHERE_NODES = 16;
// Perceptual roughness at and above which the rough form is used alone.
export const ROUGH_BLEND = 0.2;

const VERTEX = `in vec3 position;
void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }`;

const MAIN = `
uniform uint cf_words[14];
uniform vec2 cf_eta_i_range;
uniform float cf_coat_ior;
uniform float u_roughness;
uniform float u_nodes;
layout(location = 0) out vec4 out_escape;

// The metal's Fresnel: the kind's generated cf_preview_model (generated/kinds.js).
vec3 cf_escape_metal(float c)
{
    return cf_preview_model(c, cf_coat_ior, cf_eta_i_range, cf_words);
}

// The GGX lobe at in-coat cosine mu: its albedo (total) and the part of it
// leaving through the coat's underside at once (escaped).
void cf_lobe(float mu_in, int samples, out vec3 total, out vec3 escaped)
{
    float mu = max(cf_saturate(mu_in), 1.0e-6);
    vec3 V = vec3(sqrt(1.0 - mu * mu), 0.0, mu);
    float alpha_g = cf_alpha_g_from_roughness(u_roughness);
    float G1 = cf_smith_G1(mu, alpha_g);
    float inverse_eta = 1.0 / max(cf_coat_ior, 1.0);
    total = vec3(0.0);
    escaped = vec3(0.0);
    for (int i = 0; i < samples; i++)
    {
        vec3 H = cf_sample_visible_normal(V, alpha_g, cf_hammersley(i, samples));
        float VdotH = cf_saturate(dot(V, H));
        float NdotL = 2.0 * VdotH * H.z - V.z;
        if (NdotL > 0.0)
        {
            vec3 f = cf_smith_G2(mu, NdotL, alpha_g) / G1 * cf_escape_metal(VdotH);
            total += f;
            // From inside the coat: 1 beyond the critical angle.
            escaped += f * (1.0 - cf_fresnel_dielectric(NdotL, inverse_eta));
        }
    }
    total /= float(samples);
    escaped /= float(samples);
}

void main()
{
    vec3 total, escaped;
    if (int(floor(gl_FragCoord.y)) == 0)
    {
        float s = floor(gl_FragCoord.x) / max(u_nodes - 1.0, 1.0);
        cf_lobe(s * s, ${ESCAPE_SAMPLES}, total, escaped);
        vec3 q = mix(vec3(1.0), escaped / max(total, vec3(1.0e-30)), greaterThan(total, vec3(0.0)));
        out_escape = vec4(q, 1.0);
    }
    else
    {
        vec3 sum = vec3(0.0);
        for (int j = 0; j < ${HEMISPHERE_NODES}; j++)
        {
            cf_lobe(sqrt((float(j) + 0.5) / ${HEMISPHERE_NODES}.0), ${HEMISPHERE_SAMPLES}, total, escaped);
            sum += total;
        }
        out_escape = vec4(sum / ${HEMISPHERE_NODES}.0, 1.0);
    }
}
`;

/** r_bar: the cosine-weighted reflectance of a coat of index eta seen from inside (1 beyond the critical angle). */
export function internalReflectance(eta) {
  const n = Math.max(eta, 1);
  let sum = 0;
  for (let j = 0; j < HEMISPHERE_NODES; j++) {
    const c = Math.sqrt((j + 0.5) / HEMISPHERE_NODES); // from inside: index n over 1
    const s2 = n * n * (1 - c * c);
    if (s2 >= 1) { sum += 1; continue; }
    const t = Math.sqrt(1 - s2);
    const rs = (n * c - t) / (n * c + t);
    const rp = (c - n * t) / (c + n * t);
    sum += 0.5 * (rs * rs + rp * rp);
  }
  return sum / HEMISPHERE_NODES;
}

/**
 * One material's escape table: `draw(renderer, roughness)` renders it when
 * the roughness changed since the last time; `texture` is the table.
 */
export class EscapeTable {
  /** `glsl`: the package's GLSL; `kind`: the model's generated entry (kinds.js); `words`: its coefficients packed. */
  constructor(glsl, kind, model, words, nodes) {
    this.nodes = nodes;
    this.target = new THREE.WebGLRenderTarget(nodes, 2, {
      type: THREE.FloatType, format: THREE.RGBAFormat, minFilter: THREE.NearestFilter,
      magFilter: THREE.NearestFilter, depthBuffer: false, generateMipmaps: false,
    });
    this.texture = this.target.texture;
    this.uniforms = {
      cf_words: { value: words },
      cf_eta_i_range: { value: new THREE.Vector2(...model.etaIRange) },
      cf_coat_ior: { value: model.coatIor },
      u_roughness: { value: 0 },
      u_nodes: { value: nodes },
    };
    const material = new THREE.RawShaderMaterial({
      glslVersion: THREE.GLSL3, vertexShader: VERTEX,
      fragmentShader: `precision highp float;\nprecision highp int;\n${glsl}\n${kind.glsl}\n${MAIN}`,
      uniforms: this.uniforms, depthTest: false, depthWrite: false,
    });
    this.mesh = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material);
    this.mesh.frustumCulled = false;
    this.scene = new THREE.Scene();
    this.scene.add(this.mesh);
    this.camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1);
    this.drawnFor = null;
  }

  /** Render the table if `roughness` differs from the last drawn. */
  draw(renderer, roughness) {
    if (roughness === this.drawnFor) return false;
    this.uniforms.u_roughness.value = roughness;
    drawInto(renderer, this.target, this.scene, this.camera);
    this.drawnFor = roughness;
    return true;
  }

  /** The table as drawn ({nodes, data: nodes x 2 RGBA floats, row 0 first}), for the tests. */
  read(renderer) {
    const data = new Float32Array(4 * this.nodes * 2);
    renderer.readRenderTargetPixels(this.target, 0, 0, this.nodes, 2, data);
    return { nodes: this.nodes, data: Array.from(data) };
  }

  dispose() {
    this.target.dispose();
    this.mesh.geometry.dispose();
    this.mesh.material.dispose();
  }
}
