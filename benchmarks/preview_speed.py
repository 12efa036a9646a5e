"""
Preview speed: model only against the spectral reference
=========================================================

Times ``PreviewRenderer.render_preview`` of gold at eta_i = 1.5 under the
white sky with ``compare="none"`` (the model alone) and
``compare="reference"`` (split view with the spectral reference through its
cos theta table, as the service renders it: the PNG, without the Delta E and
FLIP maps), at 256, 512 and 1024 px; prints the median of ``--repeat`` runs
of each and their ratio (target: reference at most 3x the model alone).
``--per-pixel`` adds the reference image integrated at every pixel, as it
was; ``--maps`` the reference preview with the Delta E 2000 and FLIP maps.

Records the milliseconds and ratios per size in
benchmarks/results/preview_speed.json (:mod:`benchmarks.record`, with the
load average: wall-clock times on a shared machine move with it).

    .venv/bin/python benchmarks/preview_speed.py [--repeat 5] [--per-pixel] [--maps]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.fits.material import fit_material  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from preview_shaders.preview import PreviewRenderer, reference_image  # noqa: E402

SIZES = (256, 512, 1024)


def median_time(function, repeat: int) -> float:
    function()  # warm: shader compile, caches
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--material", default="Au")
    parser.add_argument("--eta-i", type=float, default=1.5)
    parser.add_argument(
        "--maps", action="store_true", help="also time the reference preview with its Delta E and FLIP maps"
    )
    parser.add_argument("--per-pixel", action="store_true", help="also time the reference integrated per pixel (slow)")
    args = parser.parse_args()
    load_at_start = load_average()
    nk = library_material(args.material)
    packed = fit_material(nk).packed
    rows = []
    with PreviewRenderer() as renderer:
        for size in SIZES:

            def render(compare, differences=False):
                return lambda: renderer.render_preview(packed, nk, args.eta_i, size, compare, differences=differences)

            model = median_time(render("none"), args.repeat)
            reference = median_time(render("reference"), args.repeat)
            per_pixel = maps = None
            if args.maps:
                maps = median_time(render("reference", True), args.repeat)
            if args.per_pixel:
                shot = renderer.render_preview(packed, nk, args.eta_i, size, "none")
                per_pixel = median_time(
                    lambda: reference_image(
                        nk,
                        shot.cos_theta,
                        shot.mask,
                        shot.radiance,
                        args.eta_i,
                        per_pixel=True,
                    ),
                    1,
                )
            rows.append((size, model, reference, per_pixel, maps))
    print(
        f"preview speed: {args.material} at eta_i {args.eta_i}, white sky, median of "
        f"{args.repeat}, machine {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}"
    )
    print()
    header = "| size | model only ms | reference preview ms | ratio |"
    header += " with Delta E + FLIP maps ms |" if args.maps else ""
    header += " per-pixel reference image alone ms |" if args.per_pixel else ""
    print(header)
    print("|---|---|---|---|" + "---|" * (args.maps + args.per_pixel))
    for size, model, reference, per_pixel, maps in rows:
        line = f"| {size} | {model * 1e3:.1f} | {reference * 1e3:.1f} | {reference / model:.2f}x |"
        if maps is not None:
            line += f" {maps * 1e3:.0f} |"
        if per_pixel is not None:
            line += f" {per_pixel * 1e3:.0f} |"
        print(line)
    figures = {
        str(size): {
            "model_ms": model * 1e3,
            "reference_ms": reference * 1e3,
            "ratio": reference / model,
            **({} if maps is None else {"maps_ms": maps * 1e3}),
            **({} if per_pixel is None else {"per_pixel_ms": per_pixel * 1e3}),
        }
        for size, model, reference, per_pixel, maps in rows
    }
    path = write_result(
        "preview_speed", figures, load_at_start, material=args.material, eta_i=args.eta_i, repeat=args.repeat
    )
    print(f"\nwrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
