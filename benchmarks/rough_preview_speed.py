"""
Rough preview start-up and speed
================================

What the rough preview costs: the split-sum LUT generated (``generate_lut``)
against read from the on-disk cache (``cached_lut``), the environment
prefilter (``prefilter_equirect`` of the 128 x 64 studio, nine slices), and
``PreviewRenderer.render_preview`` of gold at eta_i = 1.5 in the studio:
smooth, rough (roughness 0.3), coated (0.3, coat 0.1), and rough with the
spectral reference (PNG only, no Delta E / FLIP maps, as the service renders
it). Prints a table of medians of ``--repeat`` runs after one warm-up.

    .venv/bin/python benchmarks/rough_preview_speed.py [--size 256] [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fitting.fits.material import fit_material  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from fitting.shading import lut as lut_module  # noqa: E402
from preview_shaders.preview import ENVIRONMENTS, PreviewRenderer  # noqa: E402
from preview_shaders.rough import environment_equirect, prefilter_equirect  # noqa: E402


def timed(function, repeat: int, warm: bool = True) -> float:
    if warm:
        function()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as cache:
        import os

        os.environ[lut_module.CACHE_ENV] = cache
        start = time.perf_counter()
        lut_module.cached_lut()  # empty cache: generates and writes
        rows.append(("LUT, empty cache (generate + write)", time.perf_counter() - start))
        rows.append(("LUT, from the cache", timed(lut_module.cached_lut, args.repeat, warm=False)))
        nk = library_material("Au")
        packed = fit_material(nk).packed
        with PreviewRenderer() as renderer:
            studio = environment_equirect(renderer.thread, ENVIRONMENTS.index("studio"))
            rows.append(
                ("prefilter studio 128 x 64, 9 slices", timed(lambda: prefilter_equirect(studio), 1, warm=False))
            )
            cases = {
                "smooth (roughness 0)": {},
                "rough 0.3": {"roughness": 0.3},
                "coated 0.3, coat 0.1": {"roughness": 0.3, "mode": "coated", "coat_roughness": 0.1},
            }
            for name, extra in cases.items():
                rows.append(
                    (
                        f"render {args.size} px {name}",
                        timed(
                            lambda: renderer.render_preview(packed, nk, 1.5, args.size, environment="studio", **extra),
                            args.repeat,
                        ),
                    )
                )
            rows.append(
                (
                    f"render {args.size} px rough 0.3 + reference",
                    timed(
                        lambda: renderer.render_preview(
                            packed, nk, 1.5, args.size, "reference", "studio", differences=False, roughness=0.3
                        ),
                        args.repeat,
                    ),
                )
            )
    width = max(len(name) for name, _ in rows)
    print(f"{'step'.ljust(width)}  seconds")
    for name, seconds in rows:
        print(f"{name.ljust(width)}  {seconds:8.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
