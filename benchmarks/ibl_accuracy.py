"""
Split-sum accuracy: the pre-integrated directional albedo of the model
(fitting.shading.ibl, the default 16 x 64 x 64 LUT) against a seeded Monte
Carlo with the model's Fresnel (fitting.shading.monte_carlo), immersed mode,
white environment, on the 22 library conductors' default fits.

Grid: NdotV 0.05 .. 1 (12 values), roughness 0.05 .. 1 (8 values), eta_i
1, 1.5, 2, 2.5. Per point the error is |split - MC| / MC, and it "passes"
when it is <= 1 % or <= 3 standard errors. Prints the worst error per
roughness and per eta_i, and the overall worst.

Records the worst and mean relative error, the worst per roughness and per
eta_i and the points passing in benchmarks/results/ibl_accuracy.json
(:mod:`benchmarks.record`).

    .venv/bin/python benchmarks/ibl_accuracy.py [--samples 65536] [--materials Cr,Ta]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402

from fitting.fits.material import fit_material
from fitting.optics.library import LIBRARY_NAMES, library_material
from fitting.models.coated_conductor import model_parameters
from fitting.shading.ibl import default_lut, split_sum_model
from fitting.shading.monte_carlo import model_directional_albedo

NDOTV = np.array([0.05, 0.08, 0.12, 0.18, 0.25, 0.35, 0.45, 0.55, 0.65, 0.75, 0.88, 1.0])
ROUGHNESS = np.array([0.05, 0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0])
ETA_I = np.array([1.0, 1.5, 2.0, 2.5])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--samples", type=int, default=65536)
    parser.add_argument("--materials", help="comma-separated subset (default: all 22)")
    args = parser.parse_args()
    load_at_start = load_average()
    names = args.materials.split(",") if args.materials else list(LIBRARY_NAMES)
    t0 = time.perf_counter()
    params = []
    for name in names:
        packed = fit_material(library_material(name)).packed
        params.append(model_parameters(packed.coefficients.astype(np.float64), ETA_I, packed.eta_i_range))
    P = np.stack(params)  # (material, eta, parameter, channel)
    t_fit = time.perf_counter()
    lut = default_lut()
    t_lut = time.perf_counter()
    flat = P.reshape(-1, 3, 3)
    relative = np.zeros((len(ROUGHNESS),) + flat.shape[:1] + (len(NDOTV), 3))
    in_sigma = np.zeros_like(relative)
    for j, r in enumerate(ROUGHNESS):
        mc = model_directional_albedo(NDOTV, float(r), flat, args.samples, seed=j)
        split = np.stack([split_sum_model(NDOTV, r, *p, lut) for p in flat])
        relative[j] = np.abs(split - mc.mean) / np.abs(mc.mean)
        # A zero standard error (all draws equal) leaves only the 1 % test.
        in_sigma[j] = np.abs(split - mc.mean) / np.maximum(mc.stderr, 1e-300)
    t_mc = time.perf_counter()
    passes = (relative <= 0.01) | (in_sigma <= 3.0)
    shape = (len(ROUGHNESS), len(names), len(ETA_I), len(NDOTV), 3)
    rel = relative.reshape(shape)
    sig = in_sigma.reshape(shape)
    print(
        f"{len(names)} materials x {len(ETA_I)} eta_i x {len(ROUGHNESS)} roughness x "
        f"{len(NDOTV)} NdotV x RGB, {args.samples} MC samples per point"
    )
    print("\n| roughness | worst rel. error | at (material, eta_i, NdotV) | its MC stderr (rel.) |")
    print("|---|---|---|---|")
    for j, r in enumerate(ROUGHNESS):
        k = np.unravel_index(rel[j].argmax(), rel[j].shape)
        stderr_rel = rel[j][k] / max(sig[j][k], 1e-300)
        print(
            f"| {r:.2f} | {100 * rel[j][k]:.3f} % | {names[k[0]]}, {ETA_I[k[1]]:.1f}, "
            f"{NDOTV[k[2]]:.2f} | {100 * stderr_rel:.3f} % |"
        )
    print("\n| eta_i | worst rel. error |")
    print("|---|---|")
    for e, eta in enumerate(ETA_I):
        print(f"| {eta:.1f} | {100 * rel[:, :, e].max():.3f} % |")
    print(
        f"\nworst relative error {100 * rel.max():.3f} %, mean {100 * rel.mean():.4f} %; "
        f"points passing (<= 1 % or <= 3 stderr): {passes.sum()} / {passes.size}"
    )
    print(f"time: fits {t_fit - t0:.1f} s, LUT {t_lut - t_fit:.1f} s, MC {t_mc - t_lut:.1f} s")
    figures = {
        "worst_relative_error_percent": float(100 * rel.max()),
        "mean_relative_error_percent": float(100 * rel.mean()),
        "points_passing": int(passes.sum()),
        "points": int(passes.size),
        "worst_by_roughness_percent": {
            f"{r:.2f}".replace(".", "_"): float(100 * rel[j].max()) for j, r in enumerate(ROUGHNESS)
        },
        "worst_by_eta_i_percent": {
            f"{e:.1f}".replace(".", "_"): float(100 * rel[:, :, i].max()) for i, e in enumerate(ETA_I)
        },
    }
    path = write_result(
        "ibl_accuracy",
        figures,
        load_at_start,
        samples=args.samples,
        materials=len(names),
        seconds={"fits": round(t_fit - t0, 1), "lut": round(t_lut - t_fit, 1), "mc": round(t_mc - t_lut, 1)},
    )
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
