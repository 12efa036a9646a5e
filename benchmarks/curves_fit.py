"""
Fit-from-curves speed and accuracy
==================================

Times :func:`fitting.fits.curves.fit_curves` (fitting and float16 quantisation
only: the base grid is cached and the target built before the clock starts
in the service too) for sampling and solver settings, over library materials
and typical edits, and prints one table row per setting: median and 90th
percentile wall-clock milliseconds of fitting per request, the median CPU
milliseconds of the whole call (checks, target, fit and scoring; robust to
other processes sharing the cores), and the Delta E 2000 of the float16 fit
against the edited curves (mean of means, worst max) and, with a base,
against the whole blended target.

The default of :class:`fitting.fits.curves.CurveFitSettings` is the setting with
the lowest mean Delta E whose median is at most 10 ms on the reference
machine (docs/editor.md).

Run: ``.venv/bin/python benchmarks/curves_fit.py [--repeats 5] [--materials Au,Cu,...]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from fitting.domain import cos_theta_from_angle
from fitting.fits.curves import CurveFitSettings, fit_curves
from fitting.fits.curves_base import curve_base_from_nk
from fitting.optics.library import library_material

SETTINGS = [
    dict(mu_samples=m, eta_samples=e, objective=o, irls_rounds=r, quantise=True, max_nfev=n)
    for (m, e) in ((8, 4), (12, 5), (24, 7))
    for (o, r) in (("rgb", 0), ("lab", 0), ("de2000", 0), ("de2000", 2))
    for n in (200, 15)
] + [dict(mu_samples=12, eta_samples=5, objective="de2000", irls_rounds=0, quantise=False, max_nfev=15)]


def scenarios(materials: list[str]):
    """(label, base or None, curves) for each material: the edits an artist makes."""
    angle = np.linspace(0.0, 90.0, 46)
    mu = cos_theta_from_angle(angle)
    for name in materials:
        base = curve_base_from_nk(library_material(name))
        ref15 = base.rgb(mu, 1.5)
        bump = ref15.copy()
        bump[:, 0] = np.clip(bump[:, 0] + 0.08 * np.exp(-(((angle - 60.0) / 15.0) ** 2)), 0.0, 1.0)
        # The model meets 1 at grazing whatever its coefficients (Eq. 1), so
        # an artist's tint fades out towards 90 degrees.
        fade = 1.0 - (angle / 90.0) ** 4
        tint = np.clip(ref15 * (1.0 - fade[:, None] * np.array([0.0, 0.08, 0.15])), 0.0, 1.0)
        ref22 = base.rgb(mu, 2.2)
        lift = np.clip(ref22 + 0.05 * np.exp(-(((angle - 75.0) / 10.0) ** 2))[:, None], 0.0, 1.0)
        yield name, "unedited", base, [dict(eta_i=1.5, angle_deg=angle, rgb=ref15)]
        yield name, "red bump", base, [dict(eta_i=1.5, angle_deg=angle, rgb=bump)]
        yield (
            name,
            "two edits",
            base,
            [dict(eta_i=1.5, angle_deg=angle, rgb=tint), dict(eta_i=2.2, angle_deg=angle, rgb=lift)],
        )
        yield (
            name,
            "no base, 3 curves",
            None,
            [dict(eta_i=e, angle_deg=angle, rgb=base.rgb(mu, e)) for e in (1.0, 1.75, 2.5)],
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--materials", default="Au,Cu,Al,Ag,Fe,CuZn")
    args = parser.parse_args()
    materials = args.materials.split(",")
    t = time.perf_counter()
    cases = list(scenarios(materials))
    print(f"base grids for {len(materials)} materials: {time.perf_counter() - t:.2f} s (once per material)")
    print(f"{len(cases)} requests x {args.repeats} repeats per setting; fitting time = fit + quantise\n")
    header = f"{'mu':>3} {'eta':>3} {'objective':>8} {'irls':>4} {'quant':>5} {'nfev':>4} | {'median ms':>9} {'p90 ms':>7} {'call CPU ms':>11} | {'dE mean':>7} {'dE max':>7} | {'target mean':>11} {'target max':>10}"
    print(header)
    print("-" * len(header))
    default = CurveFitSettings()
    for setting in SETTINGS:
        times, cpu, means, maxes, t_means, t_maxes = [], [], [], [], [], []
        for _, _, base, curves in cases:
            for _ in range(args.repeats):
                c0 = time.process_time()
                r = fit_curves(curves, base=base, **setting)
                # fit_curves' own checks and scoring are outside the fitting time.
                cpu.append(time.process_time() - c0)
                times.append(r.timings["fit"] + r.timings["quantise"])
            means.append(r.metrics["delta_E_mean"])
            maxes.append(r.metrics["delta_E_max"])
            if "target" in r.metrics:
                t_means.append(r.metrics["target"]["delta_E_mean"])
                t_maxes.append(r.metrics["target"]["delta_E_max"])
        ms = np.array(times) * 1e3
        mark = " <- default" if all(getattr(default, k) == v for k, v in setting.items()) else ""
        print(
            f"{setting['mu_samples']:>3} {setting['eta_samples']:>3} {setting['objective']:>8} "
            f"{setting['irls_rounds']:>4} {'yes' if setting['quantise'] else 'no':>5} {setting['max_nfev']:>4} | "
            f"{statistics.median(ms):9.2f} {np.percentile(ms, 90):7.2f} {statistics.median(cpu) * 1e3:11.2f} | "
            f"{np.mean(means):7.3f} {np.max(maxes):7.3f} | {np.mean(t_means):11.3f} {np.max(t_maxes):10.3f}{mark}"
        )


if __name__ == "__main__":
    main()
