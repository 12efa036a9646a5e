"""
Cost of each Fresnel shader variant: full-screen 2560 x 1440 evaluations
into an RGBA32F target, timed with a GL timer query around finished work
(on llvmpipe a query covers only completed work, so ctx.finish() is called
inside the timed block) and with wall time. Prints each variant's median and
its ratio to adjusted Lazanyi.

    .venv/bin/python benchmarks/shader_cost.py [--repeats 15] [--material Au]

Paper (RTX 2080 Ti): model 199 us, adjusted Lazanyi 143 us (1.39x). Targets:
general model <= 1.15x, scene-specialised <= 1.05x.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fitting.baselines import baseline_inputs  # noqa: E402
from fitting.fit import fit_material  # noqa: E402
from fitting.library import library_material  # noqa: E402
from fitting.nk import resample_nk  # noqa: E402
from preview_shaders.evaluate import VARIANTS, shader_inputs, time_variant  # noqa: E402
from preview_shaders.gl import RenderThread  # noqa: E402

LABELS = {
    "packed": "model, float16 halves (general)",
    "floats": "model, float coefficients (general)",
    "collapsed": "model, scene-specialised (Eq. 1)",
    "lazanyi": "adjusted Lazanyi",
    "schlick": "Schlick",
    "exact": "exact RGB conductor Fresnel",
}
# n, k for the exact RGB Fresnel: the spectral data at these wavelengths
# (nm), a renderer's usual choice for R, G, B.
RGB_WAVELENGTHS_NM = np.array([630.0, 532.0, 465.0])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--material", default="Au")
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--width", type=int, default=2560)
    parser.add_argument("--height", type=int, default=1440)
    args = parser.parse_args()

    nk = library_material(args.material)
    packed = fit_material(nk).packed
    air = baseline_inputs(nk)
    rgb = resample_nk(nk, RGB_WAVELENGTHS_NM, 0.0)
    inputs = shader_inputs(packed, 1.5, air["F0_air"], air["F82_air"], rgb.n, rgb.k)
    with RenderThread("shader-cost") as thread:
        print(f"device: {thread.renderer}, {thread.version}")
        print(f"{args.width} x {args.height} RGBA32F, {args.material}, median of "
              f"{args.repeats} (one warm-up render before each; variants interleaved)\n")
        times = {}
        # Interleaved rounds, so drifting machine load hits every variant alike.
        samples = {v: ([], []) for v in VARIANTS}
        for _ in range(args.repeats):
            for variant in VARIANTS:
                gpu_ns, wall_s = time_variant(thread, variant, inputs, args.width, args.height,
                                              repeats=1, warmup=1)
                samples[variant][0].extend(gpu_ns)
                samples[variant][1].extend(wall_s)
        for variant in VARIANTS:
            gpu_ns, wall_s = samples[variant]
            times[variant] = (np.median(gpu_ns) / 1e3, np.median(wall_s) * 1e6)
    base_gpu, base_wall = times["lazanyi"]
    print(f"| variant | timer query (us) | ratio | wall (us) | ratio |")
    print(f"|---|---:|---:|---:|---:|")
    for variant in VARIANTS:
        gpu, wall = times[variant]
        print(f"| {LABELS[variant]} | {gpu:.0f} | {gpu / base_gpu:.2f}x | {wall:.0f} | "
              f"{wall / base_wall:.2f}x |")


if __name__ == "__main__":
    main()
