"""
Cost of the metrics of a fit
============================

For a few library conductors: CPU time (``time.process_time``, single BLAS
thread, best of ``--repeat``; CPU time, unlike wall time, is not inflated by
other work on a shared machine) of

-   the fit alone (``fit_material``),
-   the 1 nm reference on the paper's 100 x 100 grid as defined
    (``reference_ACEScg``, complex Fresnel per sample) and on the product
    grid (``reference_ACEScg_grid``, what ``evaluate_material`` uses),
-   ``evaluate_material`` (reference, float16 / float64 model, 4 baselines),

and the largest difference of the reported Delta E (mean and max, float16
model) between the two references. Prints a Markdown table.

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
    print("| material | fit ms | reference as defined ms | grid reference ms | evaluate_material ms "
          "| fit + evaluate ms | max abs diff of Delta E mean / max |")
    print("|---|---:|---:|---:|---:|---:|---|")
    with threadpool_limits(limits=1):
        for name in args.materials.split(","):
            nk = library_material(name)
            result = fit_material(nk)
            M, E = evaluation_grid(100, result.eta_i_range)
            fit = cpu_ms(lambda: fit_material(nk), args.repeat)
            slow = cpu_ms(lambda: reference_ACEScg(nk, M, E, 1.0), args.repeat)
            grid = cpu_ms(lambda: reference_ACEScg_grid(nk, M[0], E[:, 0], 1.0), args.repeat)
            evaluate = cpu_ms(lambda: evaluate_material(nk, result), args.repeat)
            model = coated_conductor_model(M, E, result.coefficients_float16, result.eta_i_range)
            a = error_metrics(reference_ACEScg(nk, M, E, 1.0), model)
            b = evaluate_material(nk, result, baselines=False)["model_float16"]
            print(f"| {name} | {fit:.1f} | {slow:.1f} | {grid:.1f} | {evaluate:.1f} | "
                  f"{fit + evaluate:.1f} | {abs(a.mean - b['delta_E_mean']):.1e} / "
                  f"{abs(a.max - b['delta_E_max']):.1e} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
