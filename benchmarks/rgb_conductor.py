"""
The rgb-conductor model kind against the coated-conductor, on the library.

For each of the 22 library conductors: the ``rgb-conductor`` fit
(``fitting.fits.rgb_conductor.fit_rgb_conductor`` with its defaults) and the
``coated-conductor`` fit (``fitting.fit_material`` with its defaults), both
scored with their float16 coefficients as ``evaluate_material`` scores them:
mean and max Delta E 2000 against the 1 nm spectral reference on the paper's
100 x 100 grid over cos theta in [0, 1] and eta_i in [1, 2.5]. Also the
rgb-conductor's float64 optimum and plain float16 rounding of it, to show
what the float16-aware rounding buys.

Recorded in benchmarks/results/rgb_conductor.json (:mod:`benchmarks.record`):
the means over the conductors of each column, how many conductors the
rgb-conductor is below the coated-conductor on, and each conductor's row.

Usage: python benchmarks/rgb_conductor.py [--materials Au,Cu] [--objective de2000]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting import LIBRARY_NAMES, fit_material, library_material  # noqa: E402
from fitting.fits.settings import OBJECTIVES  # noqa: E402
from fitting.fits.rgb_conductor import fit_rgb_conductor  # noqa: E402
from fitting.colour.delta_e import delta_E_map  # noqa: E402
from fitting.models.coated_conductor import coated_conductor_model  # noqa: E402
from fitting.models.rgb_conductor import rgb_conductor_model  # noqa: E402
from fitting.colour.reference import evaluation_grid, reference_ACEScg  # noqa: E402

ETA_I_RANGE = (1.0, 2.5)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--materials", help="comma-separated subset (default: all 22)")
    parser.add_argument("--objective", choices=OBJECTIVES, default="de2000")
    args = parser.parse_args(argv)
    load_at_start = load_average()
    names = args.materials.split(",") if args.materials else list(LIBRARY_NAMES)
    M, E = evaluation_grid(100, ETA_I_RANGE)
    rows, times = [], []
    t_all = time.perf_counter()
    for name in names:
        nk = library_material(name)
        ref = reference_ACEScg(nk, M, E, 1.0)
        rgb = fit_rgb_conductor(nk, ETA_I_RANGE, objective=args.objective)
        times.append(rgb.timings["total"])
        coated = fit_material(nk, ETA_I_RANGE, objective=args.objective)

        def score(F):
            dE = delta_E_map(ref, F)
            return float(dE.mean()), float(dE.max())

        rows.append(
            (
                name,
                score(rgb_conductor_model(M, E, rgb.coefficients_float16)),
                score(rgb_conductor_model(M, E, rgb.coefficients)),
                score(rgb_conductor_model(M, E, rgb.coefficients.astype(np.float16))),
                score(coated_conductor_model(M, E, coated.coefficients_float16, ETA_I_RANGE)),
            )
        )
    print(
        f"objective: {args.objective}; Delta E 2000 mean / max, float16 unless said, "
        "100 x 100 grid, eta_i in [1, 2.5], 1 nm reference\n"
    )
    print(
        "| conductor | rgb-conductor f16 | rgb-conductor f64 | rgb-conductor, plain f16 rounding "
        "| coated-conductor f16 | rgb-conductor better |"
    )
    print("|---|---|---|---|---|---|")
    for name, ours, f64, plain, coated in rows:
        better = "yes" if ours[0] < coated[0] else "NO"
        print(
            f"| {name} | {ours[0]:.4f} / {ours[1]:.3f} | {f64[0]:.4f} / {f64[1]:.3f} "
            f"| {plain[0]:.4f} / {plain[1]:.3f} | {coated[0]:.4f} / {coated[1]:.3f} | {better} |"
        )
    mean = lambda i: float(np.mean([r[i][0] for r in rows]))  # noqa: E731
    print(
        f"| **mean ({len(rows)})** | **{mean(1):.4f}** | {mean(2):.4f} | {mean(3):.4f} | {mean(4):.4f} | "
        f"{sum(r[1][0] < r[4][0] for r in rows)}/{len(rows)} |"
    )
    run_s = time.perf_counter() - t_all
    print(f"\nrgb-conductor fit time: median {np.median(times) * 1e3:.0f} ms per conductor; run time {run_s:.0f} s")
    columns = ("rgb_conductor_f16", "rgb_conductor_f64", "rgb_conductor_plain_f16_rounding", "coated_conductor_f16")
    figures = {
        "objective": args.objective,
        "conductors": len(rows),
        "mean": {column: mean(i + 1) for i, column in enumerate(columns)},
        "rgb_conductor_below_coated": sum(r[1][0] < r[4][0] for r in rows),
        "fit_ms_median": float(np.median(times) * 1e3),
        "conductor": {
            r[0]: {column: {"mean": r[i + 1][0], "max": r[i + 1][1]} for i, column in enumerate(columns)} for r in rows
        },
    }
    print(f"wrote {write_result('rgb_conductor', figures, load_at_start, seconds=round(run_s, 1))}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
