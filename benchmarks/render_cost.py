"""
What a preview costs in CPU
===========================

The render pool gives each preview an estimated cost and a CPU budget
proportional to it (:func:`service.jobs.previews.preview_cost_s`); this
measures what drives it, and how the estimate compares. ``PreviewRenderer.render_preview`` of gold at eta_i = 1.5 (PNG
only, as the service renders it), the CPU seconds of this process (its GL
thread and llvmpipe's threads included, as a render process's clock counts
them), for each kind of view (smooth, smooth with the spectral reference,
rough or coated, rough with the reference), each size and each environment,
after one warm render of each. Per view a line ``fixed + per_megapixel x
size^2 / 1e6`` is fitted by least squares; the worst ratio of a measured
render to that line is recorded beside it, and the worst ratio of a
measured render to the service's estimate (``worst_of_estimate``: at most 1
where the estimate is never below what was measured). Also the cold cost: the first
rough render of an environment in a fresh renderer (its shader compiled
and the environment prefiltered), less a warm one.

    .venv/bin/python benchmarks/render_cost.py [--sizes 256 512 1024 2048] [--repeat 2]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.fits.material import fit_material  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from preview_shaders.preview import ENVIRONMENTS, PreviewRenderer  # noqa: E402
from service.jobs.previews import preview_cost_s  # noqa: E402

VIEWS = {
    "smooth": {"compare": "lazanyi"},
    "smooth_reference": {"compare": "reference"},
    "rough": {"roughness": 0.3, "mode": "coated", "coat_roughness": 0.1, "compare": "lazanyi"},
    "rough_reference": {"roughness": 0.3, "mode": "coated", "coat_roughness": 0.1, "compare": "reference"},
}
"""Each kind of view at its dearest (the split with a second image; coated, which reads two environments)."""


def cpu_s(function) -> float:
    start = time.process_time()
    function()
    return time.process_time() - start


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024, 2048])
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    load_at_start = load_average()
    nk = library_material("Au")
    packed = fit_material(nk).packed
    figures: dict = {}
    with PreviewRenderer() as renderer:

        def render(size: int, environment: str, view: dict) -> None:
            renderer.render_preview(packed, nk, 1.5, size, environment=environment, differences=False, **view)

        cold = {}
        for environment in ENVIRONMENTS:
            first = cpu_s(lambda: render(64, environment, VIEWS["rough"]))
            cold[environment] = first - statistics.median(
                cpu_s(lambda: render(64, environment, VIEWS["rough"])) for _ in range(3)
            )
        figures["cold_rough_environment_s"] = {
            "typical": round(statistics.median(cold.values()), 3),
            "worst": round(max(cold.values()), 3),
        }
        for name, view in VIEWS.items():
            render(64, "white_sky", view)  # warm (its program compiled)
            rows = []
            for environment in ENVIRONMENTS:
                for size in args.sizes:
                    seconds = statistics.median(
                        cpu_s(lambda: render(size, environment, view)) for _ in range(args.repeat)
                    )
                    rows.append((environment, size, seconds))
                    print(f"{name:17s} {environment:9s} {size:5d} px  {seconds:7.3f} CPU s", flush=True)
            megapixels = np.array([size * size / 1e6 for _, size, _ in rows])
            measured = np.array([s for _, _, s in rows])
            per_mp, fixed = np.polyfit(megapixels, measured, 1)
            fixed = max(float(fixed), 0.0)
            ratio = measured / (fixed + per_mp * megapixels)
            estimates = np.array(
                [
                    preview_cost_s(
                        size, view.get("compare", "none"), view.get("roughness", 0.0), view.get("mode", "immersed")
                    )
                    for _, size, _ in rows
                ]
            )
            by_environment = {e: round(float(np.mean([s for r, _, s in rows if r == e])), 3) for e in ENVIRONMENTS}
            figures[name] = {
                "fixed_s": round(fixed, 3),
                "per_megapixel_s": round(float(per_mp), 3),
                "worst_ratio": round(float(ratio.max()), 2),
                "worst_of_estimate": round(float((measured / estimates).max()), 2),
                "largest_s": round(float(measured.max()), 3),
                "mean_by_environment_s": by_environment,
            }
    for name, values in figures.items():
        print(name, values)
    path = write_result("render_cost", figures, load_at_start, sizes=args.sizes, repeat=args.repeat)
    print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
