"""
Worst-case curve refits
=======================

Wall time of :func:`fitting.fits.curves.fit_curves` in this process for the
worst-case edits against a gentle one (each the median of ``--repeats``),
and of the live steps of a drag (``LIVE_SETTINGS``, warm-started from the
fit before, 20 steps) for each, p50 and p99:

-   ``gentle``: Au's red curve at eta_i 1.5 raised by 0.05 around 50 degrees;
-   ``Au green 0.10 at 60``: Au's green pulled to 0.10 at 60 degrees (an
    edit the model cannot follow), 16 and 46 curve samples;
-   ``Cu green 0.10 at 60``: the same on Cu;
-   ``degenerate base``: a base of n = 1, k = 0 (``{"wavelength_nm": [300,
    900], "n": [1, 1], "k": [0, 0]}``) with a flat 0.5 curve of 16 samples.

Each row also gives the CPU seconds of the full refit (its own work,
whatever else the machine does), whether the answer is a best effort,
which candidate the worst-case guard kept, and the model's range over the
scoring grid (it must stay in [0, 1]). Run: ``.venv/bin/python
benchmarks/worst_case_refits.py [--repeats 3]``; the output is recorded in
``benchmarks/results/worst_case_refits.json``. The wall figures depend on
the machine's load (recorded).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402

from fitting.fits.curves import LIVE_SETTINGS, fit_curves  # noqa: E402
from fitting.fits.curves_base import curve_base_from_nk  # noqa: E402
from fitting.fits.material import fit_material  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from fitting.optics.nk import SpectralNK  # noqa: E402


def pulled(base, channel, angle, value, samples, step=1.0):
    theta = np.linspace(0.0, 90.0, samples)
    mu = np.where(theta == 90.0, 0.0, np.cos(np.radians(theta)))
    rgb = base.rgb(mu, 1.5).copy()
    w = np.exp(-0.5 * ((theta - angle) / 9.0) ** 2) * (1 - (theta / 90) ** 6)
    w /= w.max()
    i = int(np.argmin(np.abs(theta - angle)))
    rgb[:, channel] += step * (value - rgb[i, channel]) * w
    return [{"eta_i": 1.5, "angle_deg": theta.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}]


def timed(function):
    """``function()``, its wall seconds and its CPU seconds (this process: the refit's own work)."""
    t0, c0 = time.perf_counter(), time.process_time()
    result = function()
    return result, time.perf_counter() - t0, time.process_time() - c0


def percentile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(round(q * (len(values) - 1))))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    au = curve_base_from_nk(library_material("Au"))
    cu = curve_base_from_nk(library_material("Cu"))
    void = curve_base_from_nk(SpectralNK(np.array([300.0, 900.0]), np.ones(2), np.zeros(2), name="void"))
    flat = [{"eta_i": 1.5, "angle_deg": np.linspace(0, 90, 16).tolist(), "rgb": np.full((16, 3), 0.5).tolist()}]

    def gentle(s):
        curves = pulled(au, 0, 50, 0.0, 16, 0.0)  # Au as measured, red then raised around 50 degrees
        theta = np.array(curves[0]["angle_deg"])
        bump = np.exp(-0.5 * ((theta - 50.0) / 9.0) ** 2)
        rgb = np.array(curves[0]["rgb"])
        rgb[:, 0] += 0.05 * s * bump
        curves[0]["rgb"] = rgb.clip(0, 1).tolist()
        return curves

    cases = {
        "gentle (Au red +0.05 at 50)": (au, "Au", gentle, 16),
        "Au green 0.10 at 60, 16 samples": (au, "Au", lambda s: pulled(au, 1, 60, 0.10, 16, s), 16),
        "Au green 0.10 at 60, 46 samples": (au, "Au", lambda s: pulled(au, 1, 60, 0.10, 46, s), 46),
        "Cu green 0.10 at 60, 16 samples": (cu, "Cu", lambda s: pulled(cu, 1, 60, 0.10, 16, s), 16),
        "degenerate base (n 1, k 0), 16 samples": (void, None, lambda s: flat, 16),
    }
    starts = {
        name: fit_material(library_material(name)).coefficients_float16.astype(np.float64) for name in ("Au", "Cu")
    }
    load_at_start = load_average()
    print(
        f"{'edit':<40} {'full s':>7} {'max s':>6} {'cpu s':>6} {'best':>5} {'kept':>18} {'range':>15}"
        f"   {'live p50 ms':>11} {'p99 ms':>7}"
    )
    figures = {}
    for label, (base, start_name, make, _) in cases.items():
        seconds, cpu = [], []
        for _ in range(args.repeats):
            result, wall, used = timed(lambda: fit_curves(make(1.0), base))
            seconds.append(wall)
            cpu.append(used)
        target = result.metrics["target"]
        live = []
        start = starts.get(start_name)
        if start is None:  # no library fit for the degenerate base: its own full refit
            start = result.coefficients_float16.astype(np.float64)
        for s in np.linspace(0.05, 1.0, 20):
            step, wall, _ = timed(lambda: fit_curves(make(s), base, settings=LIVE_SETTINGS, start=start))
            live.append(1000 * wall)
            start = step.coefficients_float16.astype(np.float64)
        kept = (result.metrics.get("guard") or {}).get("chosen", result.metrics["objective"])
        span = f"[{target['model_min']:.3f}, {target['model_max']:.4f}]"
        print(
            f"{label:<40} {statistics.median(seconds):>7.2f} {max(seconds):>6.2f} {statistics.median(cpu):>6.2f} "
            f"{str(result.metrics['best_effort']):>5} {kept:>18} {span:>15}   "
            f"{percentile(live, 0.5):>11.0f} {percentile(live, 0.99):>7.0f}"
        )
        figures[label] = {
            "full_s": {"median": statistics.median(seconds), "max": max(seconds)},
            "full_cpu_s": statistics.median(cpu),
            "best_effort": bool(result.metrics["best_effort"]),
            "kept": kept,
            "model_min": target["model_min"],
            "model_max": target["model_max"],
            "delta_E_mean": target["delta_E_mean"],
            "delta_E_max": target["delta_E_max"],
            "live_ms": {"p50": percentile(live, 0.5), "p99": percentile(live, 0.99)},
        }
    figures["worst_full_s"] = max(f["full_s"]["max"] for f in figures.values())
    print(f"\nload average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print("recorded:", write_result("worst_case_refits", figures, load_at_start, repeats=args.repeats))


if __name__ == "__main__":
    main()
