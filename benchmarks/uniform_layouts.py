"""
Does the way the general model's per-material values are uploaded change
its cost on llvmpipe? The lean general model (``cf_coated_conductor_lean``:
27 per-power coefficients and the two-value t map from the CPU, shipped as
three ``mat3`` and a ``vec2``) is timed with the same values in other
layouts, each the same arithmetic on the same numbers (checked: the
renders match the shipped layout's: the recorded maximum difference):

-   ``vec3``: nine ``vec3`` (per parameter and power, the three channels)
    and the ``vec2``: the quadratic coefficients as vectors.
-   ``vec4_array``: a ``vec4[9]`` array, the t map in two ``w`` slots.
-   ``std140_block``: the same nine ``vec4`` in a std140 uniform block
    (a uniform buffer).
-   ``halves``: the 27 float16 coefficients (the fit's own precision,
    so lossless) packed two per ``uint`` in a ``uvec4[4]`` (14 words) and
    the ``vec2``: 16 values read instead of 29, unpacked per pixel.

with, in the same interleaved rounds, the shipped layout, the same shader
with the values compiled in (``@const``) and lean adjusted Lazanyi with
uniforms (``cf_lazanyi_adjusted_lean``: 6 values), the like-for-like
baseline of :mod:`benchmarks.shader_cost`. Per round, each layout's
process CPU time over lean adjusted Lazanyi's; median over rounds with a
95 % bootstrap interval.

    .venv/bin/python benchmarks/uniform_layouts.py [--repeats 20]

Recorded in benchmarks/results/uniform_layouts.json with the load average.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.shader_cost import paired_ratio  # noqa: E402
from fitting.fits.material import fit_material  # noqa: E402
from fitting.models.baselines import baseline_inputs  # noqa: E402
from fitting.models.coated_conductor import lean_constants  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from preview_shaders.evaluate import CONSTANTS_SUFFIX, _timing_program, shader_inputs  # noqa: E402
from preview_shaders.gl import RenderThread, load_shader_source, time_renders  # noqa: E402

_BODY = """
    vec3 F0 = Q0 + t * (Q1 + t * Q2);
    vec3 a = Q3 + t * (Q4 + t * Q5);
    vec3 alpha = max(Q6 + t * (Q7 + t * Q8), vec3(CF_ALPHA_MIN));
    vec3 F = cf_coated_conductor_eq1_lean(NdotV, F0, a, alpha);
"""
_HALF = [f"h{i // 2}.{'xy'[i % 2]}" for i in range(27)]
_UNPACK = "".join(f"    vec2 h{i} = unpackHalf2x16(cf_h[{i // 4}].{'xyzw'[i % 4]});\n" for i in range(14)) + "".join(
    f"    vec3 Q{p} = vec3({', '.join(_HALF[3 * p : 3 * p + 3])});\n" for p in range(9)
)
LAYOUTS = {
    # name: (declarations, per-pixel t and the nine Q vectors)
    "vec3": (
        "uniform vec3 " + ", ".join(f"Q{i}" for i in range(9)) + ";\nuniform vec2 cf_t_map;\n",
        "    float t = clamp(eta_i * cf_t_map.x + cf_t_map.y, 0.0, 1.0);\n",
    ),
    "vec4_array": (
        "uniform vec4 cf_v[9];\n" + "".join(f"#define Q{i} cf_v[{i}].xyz\n" for i in range(9)),
        "    float t = clamp(eta_i * cf_v[0].w + cf_v[1].w, 0.0, 1.0);\n",
    ),
    "std140_block": (
        "layout(std140) uniform CF { vec4 cf_b[9]; };\n" + "".join(f"#define Q{i} cf_b[{i}].xyz\n" for i in range(9)),
        "    float t = clamp(eta_i * cf_b[0].w + cf_b[1].w, 0.0, 1.0);\n",
    ),
    "halves": (
        "uniform uvec4 cf_h[4];\nuniform vec2 cf_t_map;\n",
        "    float t = clamp(eta_i * cf_t_map.x + cf_t_map.y, 0.0, 1.0);\n" + _UNPACK,
    ),
}
BASELINE = "lazanyi_lean"
SHIPPED = ("lean", "lean" + CONSTANTS_SUFFIX)


def fragment(layout: str) -> str:
    declarations, head = LAYOUTS[layout]
    return (
        '#version 430\n#include "cf_coated_conductor.glsl"\nuniform vec4 u_grid;\n'
        + declarations
        + "layout(location = 0) out vec4 out_F;\nvoid main()\n{\n"
        "    vec2 index = floor(gl_FragCoord.xy);\n"
        "    float NdotV = u_grid.x + index.x * u_grid.y;\n"
        "    float eta_i = u_grid.z + index.y * u_grid.w;\n" + head + _BODY + "    out_F = vec4(F, 1.0);\n}\n"
    )


def _set_values(ctx, program, layout: str, P: np.ndarray, t_map, keep: list) -> None:
    rows = P.reshape(9, 3)  # parameter-major, then power: Q0..Q8
    vec4s = np.zeros((9, 4), np.float32)
    vec4s[:, :3] = rows
    vec4s[0, 3], vec4s[1, 3] = t_map
    if layout == "vec3":
        for i in range(9):
            program[f"Q{i}"].value = tuple(float(v) for v in rows[i])
    elif layout == "vec4_array":
        program["cf_v"].write(vec4s.tobytes())
    elif layout == "std140_block":
        buffer = ctx.buffer(vec4s.tobytes())
        keep.append(buffer)
        buffer.bind_to_uniform_block(0)
        program["CF"].binding = 0
    elif layout == "halves":
        halves = np.zeros(32, np.float16)
        halves[:27] = rows.ravel()
        program["cf_h"].write(halves.view(np.uint32).tobytes())
    if "cf_t_map" in program:
        program["cf_t_map"].value = tuple(float(v) for v in t_map)


def _run(state, inputs, P, t_map, width, height, rounds):
    ctx = state.ctx
    keep: list = []
    programs = {name: _timing_program(state, name, inputs) for name in (BASELINE, *SHIPPED)}
    for layout in LAYOUTS:
        program = ctx.program(
            vertex_shader=load_shader_source("fullscreen.vert"),
            fragment_shader=load_shader_source("layout.frag", None, {"layout.frag": fragment(layout)}),
        )
        _set_values(ctx, program, layout, P, t_map, keep)
        programs[layout] = (program, ctx.vertex_array(program, []))
    fbo, targets = state.float_targets((width, height), 1)
    try:
        fbo.use()
        renders = {}
        for name, (program, vao) in programs.items():
            program["u_grid"].value = (0.0, 1.0 / (width - 1), 1.0, 1.5 / (height - 1))
            vao.render(mode=ctx.TRIANGLES, vertices=3)
            renders[name] = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32)
        samples = time_renders(ctx, {name: vao for name, (_, vao) in programs.items()}, rounds)
    finally:
        state.release_targets(fbo, targets)
        for buffer in keep:
            buffer.release()
    difference = {name: float(np.abs(renders[name] - renders["lean"]).max()) for name in programs if name != BASELINE}
    return samples, difference


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--material", default="Au")
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--width", type=int, default=2560)
    parser.add_argument("--height", type=int, default=1440)
    args = parser.parse_args()
    load_at_start = load_average()
    nk = library_material(args.material)
    air = baseline_inputs(nk)
    inputs = shader_inputs(fit_material(nk).packed, 1.5, air["F0_air"], air["F82_air"])
    P, t_map = lean_constants(inputs.coefficients.reshape(3, 3, 3), inputs.eta_i_range)
    with RenderThread("uniform-layouts") as thread:
        device = f"{thread.renderer}, {thread.version}"
        samples, difference = thread.call(_run, inputs, P, t_map, args.width, args.height, args.repeats)
    rng = np.random.default_rng(0)
    names = (*SHIPPED, *LAYOUTS)
    print(f"device: {device}\n{args.width} x {args.height}, {args.material}, {args.repeats} rounds\n")
    print("| layout | CPU (ms) | CPU ratio to lean adjusted Lazanyi [95 %] | max difference from shipped |")
    print("|---|---:|---:|---:|")
    layouts = {}
    for name in names:
        cpu = samples[name][:, 2]
        ratio = paired_ratio(cpu, samples[BASELINE][:, 2], rng)
        layouts[name] = {
            "cpu_ms": float(np.median(cpu) * 1e3),
            "cpu_ratio": ratio,
            "max_difference": difference[name],
        }
        print(
            f"| {name} | {layouts[name]['cpu_ms']:.1f} | {ratio['median']:.2f} [{ratio['low']:.2f}, "
            f"{ratio['high']:.2f}] | {layouts[name]['max_difference']:.1e} |"
        )
    figures = {"device": device, "baseline_cpu_ms": float(np.median(samples[BASELINE][:, 2]) * 1e3), "layouts": layouts}
    path = write_result(
        "uniform_layouts",
        figures,
        load_at_start,
        material=args.material,
        repeats=args.repeats,
        size=[args.width, args.height],
    )
    print(f"\nwrote {path}")


if __name__ == "__main__":
    main()
