"""
Cost of the metrics of a fit
============================

For a few library conductors: CPU time (``time.process_time``, single BLAS
thread, best of ``--repeat``; CPU time, unlike wall time, is not inflated by
other work on a shared machine) of

-   the fit alone (``fit_material``),
-   the 1 nm reference on the paper's 100 x 100 grid as defined
    (``reference_ACEScg``, complex Fresnel per sample) and on the product
    grid (``reference_ACEScg_grid``, what ``evaluate_material`` uses), in
    float64 and in float32 (what the service uses),
-   ``evaluate_material`` (reference, float16 / float64 model, 4 baselines),
    float64 and float32,

and the largest difference of the reported Delta E (mean and max, float16
model) from the definition's, for the float64 and the float32 reference.
One thread (CPU time does not show the service's second thread). Prints a
Markdown table.

    .venv/bin/python benchmarks/metrics_speed.py [--materials Au,Cu,Cr] [--repeat 3]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from threadpoolctl import threadpool_limits  # noqa: E402

from fitting.colour.reference import evaluation_grid, reference_ACEScg, reference_ACEScg_grid  # noqa: E402
from fitting.fits.evaluate import evaluate_material  # noqa: E402
from fitting.fits.material import fit_material  # noqa: E402
from fitting.fits.metrics import error_metrics  # noqa: E402
from fitting.models.coated_conductor import coated_conductor_model  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402


def cpu_ms(function, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        function()
        best = min(best, time.process_time() - start)
    return best * 1e3


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--materials", default="Au,Cu,Cr")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(
        "| material | fit ms | reference as defined ms | grid reference ms (float32) "
        "| evaluate_material ms (float32) | fit + evaluate ms (float32) "
        "| Delta E mean / max minus the definition's: float64 | float32 |"
    )
    print("|---|---:|---:|---:|---:|---:|---|---|")
    with threadpool_limits(limits=1):
        for name in args.materials.split(","):
            nk = library_material(name)
            result = fit_material(nk)
            M, E = evaluation_grid(100, result.eta_i_range)
            fit = cpu_ms(lambda: fit_material(nk), args.repeat)
            slow = cpu_ms(lambda: reference_ACEScg(nk, M, E, 1.0), args.repeat)
            grid, grid32 = (
                cpu_ms(lambda: reference_ACEScg_grid(nk, M[0], E[:, 0], 1.0, dtype=dtype), args.repeat)
                for dtype in ("float64", "float32")
            )
            evaluate, evaluate32 = (
                cpu_ms(lambda: evaluate_material(nk, result, dtype=dtype), args.repeat)
                for dtype in ("float64", "float32")
            )
            model = coated_conductor_model(M, E, result.coefficients_float16, result.eta_i_range)
            a = error_metrics(reference_ACEScg(nk, M, E, 1.0), model)
            diffs = []
            for dtype in ("float64", "float32"):
                b = evaluate_material(nk, result, baselines=False, dtype=dtype)["model_float16"]
                diffs.append(f"{abs(a.mean - b['delta_E_mean']):.1e} / {abs(a.max - b['delta_E_max']):.1e}")
            print(
                f"| {name} | {fit:.1f} | {slow:.1f} | {grid:.1f} ({grid32:.1f}) | {evaluate:.1f} "
                f"({evaluate32:.1f}) | {fit + evaluate:.1f} ({fit + evaluate32:.1f}) | "
                f"{diffs[0]} | {diffs[1]} |"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
