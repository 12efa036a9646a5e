"""
Cost of each Fresnel shader variant: full-screen 2560 x 1440 evaluations of
``preview_shaders/glsl/evaluate.frag`` into an RGBA32F target (cos theta
across the screen, eta_i in [1, 2.5] down it, coefficients and material
inputs as uniforms, as a renderer feeds them). Each render is timed three
ways: a GL timer query around finished work (on llvmpipe a query covers only
completed work, so ctx.finish() is called inside it), wall time, and the
process's CPU time (on llvmpipe: the rasteriser threads' work, which other
processes' load disturbs less than the wall time).

    .venv/bin/python benchmarks/shader_cost.py [--repeats 25] [--material Au]

Fairness:

-   A pass with no Fresnel term (``CF_VARIANT`` 7: the same grid inputs and
    RGBA32F store) is timed with the variants. Its time is the pass's fixed
    cost (rasterisation, inputs, store, finish), paid alike by every
    variant; the "net" ratios subtract it from both sides, so they compare
    the Fresnel terms alone. Raw ratios are printed too.
-   Adjusted Lazanyi computes what a renderer computes when eta_i varies per
    pixel: the external-medium F0 from eta_i in the shader. The
    scene-specialised model (eta_i constant, F0, a, alpha collapsed on the
    CPU) is also compared with Lazanyi at the same constant eta_i, whose F0
    and a are likewise computed on the CPU (``CF_VARIANT`` 6).
-   Variants are interleaved round by round, one warm-up render before each
    timed one, so drifting machine load hits every variant alike.
-   Like for like, each model form is paired with the adjusted Lazanyi form
    that gets the same help from the CPU: the lean general model
    (``cf_coated_conductor_lean``: per-power coefficients and the t map from
    the CPU) with ``cf_lazanyi_adjusted_lean`` (the equivalent index n and a
    from the CPU), each with its inputs as uniforms and, as a second pair,
    compiled in as GLSL constants (``@const``: what an exported material
    snippet ships; ``cf_coated_conductor`` with ``cf_lazanyi_adjusted``).
    On llvmpipe every uniform component is loaded per pixel, so the forms
    with uniforms pay per value read (29 for the general model, 6 for
    Lazanyi), the compiled-in forms do not.
-   Each pair's ratio is taken per round (both renders of a round ran under
    the same load) and reported as the median over rounds with a 95 %
    bootstrap interval of that median (10 000 resamples of the rounds), for
    the process CPU time and the wall time.

Paper (RTX 2080 Ti): model 199 us, adjusted Lazanyi 143 us (1.39x). Targets
here: general model <= 1.8x, scene-specialised <= 1.05x of adjusted Lazanyi
like for like.

Recorded in benchmarks/results/shader_cost.json (:mod:`benchmarks.record`):
the device, and per variant its medians and ratios as printed, with the load
average (wall times on llvmpipe move with the machine's other work).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fitting.fits.material import fit_material
from fitting.fits.rgb_conductor import fit_rgb_conductor, rgb_nk
from fitting.models.baselines import baseline_inputs, external_medium_F0, lazanyi_a
from fitting.models.coated_conductor import collapse_to_eta_i
from fitting.models.pack import halves_to_uint32
from fitting.shading.ibl import default_lut
from fitting.optics.library import library_material
from preview_shaders.evaluate import (  # noqa: E402
    CONSTANTS_SUFFIX,
    FIXED,
    LAZANYI_SCENE,
    TIMING_VARIANTS,
    shader_inputs,
    time_variants,
)
from preview_shaders.gl import RenderThread  # noqa: E402
from benchmarks.record import load_average, write_result  # noqa: E402
from preview_shaders.shading import SPLIT_SUM_VARIANTS, time_split_sum  # noqa: E402

LABELS = {
    "packed": "model, float16 halves (general)",
    "floats": "model, float coefficients (general)",
    "collapsed": "model, scene-specialised (Eq. 1)",
    "lazanyi": "adjusted Lazanyi",
    "schlick": "Schlick",
    "exact": "exact RGB conductor Fresnel",
    "rgb_conductor": "rgb-conductor kind, float16 halves",
    LAZANYI_SCENE: "adjusted Lazanyi, scene eta_i (F0, a from CPU)",
    FIXED: "no Fresnel term (fixed cost of the pass)",
    "lean": "model, lean general (CPU constants)",
    "collapsed_lean": "model, lean scene-specialised",
    "lazanyi_lean": "adjusted Lazanyi, lean (n, a from CPU)",
}
CONSTANT_FORMS = (
    "packed",
    "floats",
    "lean",
    "collapsed",
    "collapsed_lean",
    "lazanyi",
    "lazanyi_lean",
    LAZANYI_SCENE,
    "schlick",
)
"""The variants also timed with the material's values compiled in (``@const``)."""
C = CONSTANTS_SUFFIX
PAIRS = {
    # name: (variant, its like-for-like adjusted Lazanyi)
    "general_halves_uniforms": ("packed", "lazanyi"),
    "general_floats_uniforms": ("floats", "lazanyi"),
    "general_lean_uniforms": ("lean", "lazanyi_lean"),
    "general_constants": ("floats" + C, "lazanyi" + C),
    "general_lean_constants": ("lean" + C, "lazanyi_lean" + C),
    "general_halves_constants": ("packed" + C, "lazanyi" + C),
    "specialised_uniforms": ("collapsed", "lazanyi"),
    "specialised_lean_uniforms": ("collapsed_lean", "lazanyi"),
    "specialised_lean_constants": ("collapsed_lean" + C, "lazanyi" + C),
    "specialised_lean_against_lazanyi_scene": ("collapsed_lean", LAZANYI_SCENE),
    "specialised_lean_against_lazanyi_scene_constants": ("collapsed_lean" + C, LAZANYI_SCENE + C),
    "schlick_uniforms": ("schlick", "lazanyi"),
    "schlick_constants": ("schlick" + C, "lazanyi" + C),
}


def paired_ratio(numerator: np.ndarray, denominator: np.ndarray, rng) -> dict[str, float]:
    """Median over rounds of the per-round ratio, with its 95 % bootstrap interval."""
    r = numerator / denominator
    boot = np.median(r[rng.integers(0, r.size, size=(10_000, r.size))], axis=1)
    low, high = np.percentile(boot, [2.5, 97.5])
    return {
        "median": float(np.median(r)),
        "low": float(low),
        "high": float(high),
        "ratio_of_medians": float(np.median(numerator) / np.median(denominator)),
    }


SPLIT_LABELS = {
    "split_sum_model": "split sum, model (3 alpha lookups, 24 fetches)",
    "split_sum_lazanyi": "split sum, adjusted Lazanyi (alpha = 6, 8 fetches)",
    "split_sum_schlick": "split sum, Schlick (8 fetches)",
    "split_sum_fixed": "no split sum (fixed cost of the pass)",
}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--material", default="Au")
    parser.add_argument("--repeats", type=int, default=25)
    parser.add_argument("--width", type=int, default=2560)
    parser.add_argument("--height", type=int, default=1440)
    args = parser.parse_args()
    load_at_start = load_average()

    nk = library_material(args.material)
    packed = fit_material(nk).packed
    air = baseline_inputs(nk)
    # The exact RGB Fresnel gets the project's per-channel index (fitting.models.rgb_conductor).
    n_rgb, k_rgb = rgb_nk(nk)
    inputs = shader_inputs(packed, 1.5, air["F0_air"], air["F82_air"], n_rgb, k_rgb)
    # The rgb-conductor kind decodes its own fitted float16 n, k (3 words).
    rgb_words = halves_to_uint32(fit_rgb_conductor(nk).coefficients_float16)
    inputs = dataclasses.replace(inputs, rgb_words=rgb_words)
    lut = default_lut()
    F0, a, alpha = collapse_to_eta_i(packed.coefficients.astype(np.float64), 1.5, packed.eta_i_range)[..., 0]
    with RenderThread("shader-cost") as thread:
        device = f"{thread.renderer}, {thread.version}"
        print(f"device: {device}")
        print(
            f"{args.width} x {args.height} RGBA32F, {args.material}, median of "
            f"{args.repeats} (one warm-up render before each; variants interleaved); "
            f"scene eta_i {inputs.collapse_eta_i}\n"
        )
        names = TIMING_VARIANTS + tuple(v + CONSTANTS_SUFFIX for v in CONSTANT_FORMS)
        samples = time_variants(thread, inputs, names, args.width, args.height, args.repeats)
        split = time_split_sum(
            thread,
            lut,
            F0,
            a,
            alpha,
            external_medium_F0(air["F0_air"], 1.5),
            lazanyi_a(air["F0_air"], air["F82_air"]),
            air["F0_air"],
            args.width,
            args.height,
            args.repeats,
        )

    # Medians in ms (timer query in us); quartiles of the wall time.
    query = {v: np.median(s[:, 0]) / 1e3 for v, s in samples.items()}
    wall = {v: np.median(s[:, 1]) * 1e3 for v, s in samples.items()}
    wall_q = {v: np.percentile(s[:, 1], [25, 75]) * 1e3 for v, s in samples.items()}
    cpu = {v: np.median(s[:, 2]) * 1e3 for v, s in samples.items()}

    def ratio(times, variant, base="lazanyi", net=False):
        fixed = times[FIXED] if net else 0.0
        return (times[variant] - fixed) / (times[base] - fixed)

    print("Ratios to adjusted Lazanyi; net = with the fixed cost of the pass subtracted from both sides.\n")
    print("| variant | timer query (us) | wall (ms) [IQR] | wall ratio | wall net ratio | CPU (ms) | CPU net ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for v in names:
        net = "" if v == FIXED else f"{ratio(wall, v, net=True):.2f}x"
        cpu_net = "" if v == FIXED else f"{ratio(cpu, v, net=True):.2f}x"
        label = LABELS[v.removesuffix(C)] + (", compiled-in constants" if v.endswith(C) else "")
        print(
            f"| {label} | {query[v]:.0f} | {wall[v]:.1f} [{wall_q[v][0]:.1f}, "
            f"{wall_q[v][1]:.1f}] | {ratio(wall, v):.2f}x | {net} | {cpu[v]:.1f} | {cpu_net} |"
        )
    print(
        "\nScene-specialised model against Lazanyi at the same constant eta_i: "
        f"wall {ratio(wall, 'collapsed', LAZANYI_SCENE):.2f}x, "
        f"net {ratio(wall, 'collapsed', LAZANYI_SCENE, net=True):.2f}x; "
        f"CPU net {ratio(cpu, 'collapsed', LAZANYI_SCENE, net=True):.2f}x"
    )

    rng = np.random.default_rng(0)
    pairs: dict[str, dict] = {
        name: {
            "variant": v,
            "against": base,
            "cpu": paired_ratio(samples[v][:, 2], samples[base][:, 2], rng),
            "wall": paired_ratio(samples[v][:, 1], samples[base][:, 1], rng),
        }
        for name, (v, base) in PAIRS.items()
    }
    print("\nLike for like, per-round ratios: median [95 % bootstrap interval]\n")
    print("| pair | against | CPU ratio | wall ratio |")
    print("|---|---|---:|---:|")
    for name, pair in pairs.items():
        cells = [f"{pair[k]['median']:.3f} [{pair[k]['low']:.3f}, {pair[k]['high']:.3f}]" for k in ("cpu", "wall")]
        print(f"| {pair['variant']} | {pair['against']} | {cells[0]} | {cells[1]} |")

    # The split-sum passes (NdotV across, roughness down; eta_i 1.5 collapsed on the CPU).
    sq = {v: np.median(s[:, 0]) / 1e3 for v, s in split.items()}
    sw = {v: np.median(s[:, 1]) * 1e3 for v, s in split.items()}
    sc = {v: np.median(s[:, 2]) * 1e3 for v, s in split.items()}
    fixed = "split_sum_fixed"
    print(
        "\nSplit-sum lookups (fitting.shading.ibl LUT, 16 x 64 x 64 RGB32F 3D texture, "
        "texelFetch); net ratio to adjusted Lazanyi's split sum, fixed cost subtracted.\n"
    )
    print("| variant | timer query (us) | wall (ms) | wall net ratio | CPU (ms) | CPU net ratio |")
    print("|---|---:|---:|---:|---:|---:|")

    def net(times, v):
        return (times[v] - times[fixed]) / (times["split_sum_lazanyi"] - times[fixed])

    for v in SPLIT_SUM_VARIANTS:
        wn = "" if v == fixed else f"{net(sw, v):.2f}x"
        cn = "" if v == fixed else f"{net(sc, v):.2f}x"
        print(f"| {SPLIT_LABELS[v]} | {sq[v]:.0f} | {sw[v]:.1f} | {wn} | {sc[v]:.1f} | {cn} |")

    figures = {
        "device": device,
        "variant": {
            v: {
                "wall_ms": float(wall[v]),
                "cpu_ms": float(cpu[v]),
                "wall_ratio": float(ratio(wall, v)),
                **(
                    {}
                    if v == FIXED
                    else {
                        "wall_net_ratio": float(ratio(wall, v, net=True)),
                        "cpu_net_ratio": float(ratio(cpu, v, net=True)),
                    }
                ),
            }
            for v in names
        },
        "pairs": pairs,
        "scene_specialised_against_lazanyi_scene": {
            "wall_ratio": float(ratio(wall, "collapsed", LAZANYI_SCENE)),
            "wall_net_ratio": float(ratio(wall, "collapsed", LAZANYI_SCENE, net=True)),
            "cpu_net_ratio": float(ratio(cpu, "collapsed", LAZANYI_SCENE, net=True)),
        },
        "split_sum": {
            v: {
                "wall_ms": float(sw[v]),
                "cpu_ms": float(sc[v]),
                **({} if v == fixed else {"wall_net_ratio": float(net(sw, v)), "cpu_net_ratio": float(net(sc, v))}),
            }
            for v in SPLIT_SUM_VARIANTS
        },
    }
    path = write_result(
        "shader_cost",
        figures,
        load_at_start,
        material=args.material,
        repeats=args.repeats,
        size=[args.width, args.height],
    )
    print(f"\nwrote {path}")


if __name__ == "__main__":
    main()
