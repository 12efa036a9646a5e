"""
Fit time and accuracy: our pipeline against a straightforward implementation
of the paper's.

Straightforward pipeline (Vernooij 2024, Section 3, as written): reference at
1 nm on a 100 x 100 grid of cos theta x eta_i, Eq. 2 in eta_i itself, TRF with
a 2-point finite-difference Jacobian, linear RGB residuals, coefficients
rounded to float16 at the end. Ours: ``fitting.fit_material`` with its
defaults. Both run in this process on the same machine; times are wall-clock
medians over the conductors, reference generation and fitting apart. Delta E
2000 is scored for both on the paper's 100 x 100 grid against the 1 nm
reference, with the float16 coefficients.

Recorded in benchmarks/results/fit_speed.json (:mod:`benchmarks.record`):
the medians and means of the summary, with the load average (wall-clock
times: the machine's other work shows in them).

Usage: python benchmarks/fit_speed.py [--materials Au,Cu] [--repeats 3]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting import LIBRARY_NAMES, fit_material, library_material
from fitting.colour.reference import evaluation_grid, reference_ACEScg
from fitting.domain import DEFAULT_ETA_I_RANGE
from fitting.fits.metrics import error_metrics
from fitting.models.coated_conductor import coated_conductor_model, model_from_parameters

ETA_I_RANGE = DEFAULT_ETA_I_RANGE


def naive_model(x, mu, eta):
    """Eq. 1 with Eq. 2 in eta_i itself: x[p, c, j] * eta_i ** j."""
    C = x.reshape(3, 3, 3)
    powers = np.stack([np.ones_like(eta), eta, eta * eta], axis=-1)
    P = np.einsum("sj,pcj->spc", powers, C)
    return model_from_parameters(mu[:, None], P[:, 0], P[:, 1], P[:, 2])


def naive_fit(nk):
    """The paper's pipeline, implemented straightforwardly."""
    t0 = time.perf_counter()
    M, E = evaluation_grid(100, ETA_I_RANGE)
    mu, eta = M.ravel(), E.ravel()
    target = reference_ACEScg(nk, mu, eta, step_nm=1.0)
    t1 = time.perf_counter()
    x0 = np.zeros((3, 3, 3))
    x0[0, :, 0] = reference_ACEScg(nk, 1.0, 1.0)
    x0[2, :, 0] = 6.0
    result = least_squares(
        lambda x: (naive_model(x, mu, eta) - target).ravel(),
        x0.ravel(),
        method="trf",
        jac="2-point",
    )
    C16 = result.x.astype(np.float16)
    t2 = time.perf_counter()
    return C16, t1 - t0, t2 - t1


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--materials", help="comma-separated subset (default: all 22)")
    parser.add_argument("--repeats", type=int, default=3, help="timing repeats of our fit")
    args = parser.parse_args(argv)
    load_at_start = load_average()
    names = args.materials.split(",") if args.materials else LIBRARY_NAMES
    fit_material(library_material(names[0]))  # warm caches (colour-science, weights)
    M, E = evaluation_grid(100, ETA_I_RANGE)
    rows = []
    print(
        f"{'material':8s} {'naive ref':>10s} {'naive fit':>10s} {'naive dE':>9s} "
        f"{'ours ref':>9s} {'ours fit':>9s} {'ours total':>10s} {'ours dE':>8s}"
    )
    for name in names:
        nk = library_material(name)
        ref = reference_ACEScg(nk, M, E)
        C16, naive_ref, naive_fit_s = naive_fit(nk)
        naive_dE = error_metrics(ref, naive_model(C16.astype(np.float64), M.ravel(), E.ravel()).reshape(ref.shape)).mean
        runs = [fit_material(nk, ETA_I_RANGE) for _ in range(args.repeats)]
        best = min(runs, key=lambda r: r.timings["total"])
        ours_total = float(np.median([r.timings["total"] for r in runs]))
        ours_ref = float(np.median([r.timings["reference"] for r in runs]))
        ours_dE = error_metrics(ref, coated_conductor_model(M, E, best.coefficients_float16, ETA_I_RANGE)).mean
        rows.append((naive_ref, naive_fit_s, naive_dE, ours_ref, ours_total - ours_ref, ours_total, ours_dE))
        print(
            f"{name:8s} {naive_ref * 1e3:8.1f}ms {naive_fit_s * 1e3:8.1f}ms {naive_dE:9.4f} "
            f"{ours_ref * 1e3:7.1f}ms {(ours_total - ours_ref) * 1e3:7.1f}ms {ours_total * 1e3:8.1f}ms {ours_dE:8.4f}",
            flush=True,
        )
    a = np.array(rows)
    med = np.median(a, axis=0)
    naive_total = np.median(a[:, 0] + a[:, 1])
    print()
    print(f"median over {len(names)} conductors")
    print(
        f"  straightforward: reference {med[0] * 1e3:.1f} ms + fit {med[1] * 1e3:.1f} ms = {naive_total * 1e3:.1f} ms, "
        f"mean Delta E 2000 {a[:, 2].mean():.4f}"
    )
    print(
        f"  ours:            reference {med[3] * 1e3:.1f} ms + fit {med[4] * 1e3:.1f} ms = {med[5] * 1e3:.1f} ms, "
        f"mean Delta E 2000 {a[:, 6].mean():.4f}"
    )
    print(
        f"  speed-up (median total): {naive_total / med[5]:.1f}x; ours no worse on "
        f"{int(np.sum(a[:, 6] <= a[:, 2] + 1e-12))}/{len(names)} conductors"
    )
    figures = {
        "conductors": len(names),
        "straightforward_ms": {"reference": med[0] * 1e3, "fit": med[1] * 1e3, "total": naive_total * 1e3},
        "ours_ms": {"reference": med[3] * 1e3, "fit": med[4] * 1e3, "total": med[5] * 1e3},
        "straightforward_delta_E_mean": float(a[:, 2].mean()),
        "ours_delta_E_mean": float(a[:, 6].mean()),
        "speed_up": float(naive_total / med[5]),
        "ours_no_worse": int(np.sum(a[:, 6] <= a[:, 2] + 1e-12)),
    }
    print(f"wrote {write_result('fit_speed', figures, load_at_start, repeats=args.repeats)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
