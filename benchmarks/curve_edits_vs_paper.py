"""
Curve edits: the default refit against the paper's own fitting method
======================================================================

For a set of edits (several materials, one to four edited curves, gentle
and extreme), both fits are scored on the whole blended target
(fitting.fits.curves.whole_target_error: mean Delta E 2000 over 46 angles x 31
eta_i of fitting.fits.curves_base.edited_target):

-   ``default``: fitting.fits.curves.fit_curves with its default settings (what
    the editor and POST /fits/from-curves run);
-   ``paper``: the paper's method (Vernooij 2024, Section 4: plain rgb
    least squares of the model) fitted to the blended target sampled on the
    scoring grid itself (fitting.fits.solver.fit_coefficients, objective "rgb",
    float16 quantised).

Also reported: both fits' max, the default fit's range over the grid (it
must stay in [0, 1]), whether the paper's fit is a reflectance (proven in
[0, 1] over the whole domain: an extreme edit's unconstrained rgb fit reads
up to 1.12, which a reflectance pack cannot ship) and the refit's time. The
counts: edits where the default is worse than the paper's method on the
mean or on the max, and among those, where the paper's fit is a
reflectance. Run: ``.venv/bin/python benchmarks/curve_edits_vs_paper.py``
(``--quick`` for every fourth edit); recorded in
``benchmarks/results/curve_edits_vs_paper.json``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from fitting import (  # noqa: E402
    CurveFitSettings,
    RGBCurve,
    curve_base_from_nk,
    edited_target,
    fit_coefficients,
    fit_curves,
    library_material,
)
from fitting.fits.curves import score_grid, whole_target_error  # noqa: E402
from fitting.fits.curves_range import proven_in_range  # noqa: E402
from benchmarks.record import load_average, write_result  # noqa: E402

ANGLES = np.linspace(0.0, 90.0, 46)
MU = np.where(ANGLES == 90.0, 0.0, np.cos(np.radians(ANGLES)))


def bump(centre_deg: float, width_deg: float = 9.0) -> np.ndarray:
    w = np.exp(-0.5 * ((ANGLES - centre_deg) / width_deg) ** 2) * (1 - (ANGLES / 90) ** 6)
    return w / w.max()


def edit_curve(base, eta_i, kind, channel, centre, amount):
    rgb = base.rgb(MU, eta_i).copy()
    w = bump(centre)
    if kind == "add":
        rgb[:, channel] += amount * w
    elif kind == "scale":  # "All three": the three channels scaled
        rgb *= 1.0 + amount * w[:, None]
    elif kind == "to":  # pull a point to a value
        rgb[:, channel] += (amount - rgb[np.argmin(np.abs(ANGLES - centre)), channel]) * w
    return RGBCurve.from_angles(eta_i, ANGLES, np.clip(rgb, 0.0, 1.0))


def edits():
    """(label, material, [curve specs]) of the benchmark's edits."""
    out = []
    etas = [1.5, 1.2, 2.0, 2.4]
    for material in ("Au", "Cu", "Al", "Cr", "Ag"):
        for n in (1, 2, 4):
            at = etas[:n]
            out.append((f"{material} {n} gentle", material, [("add", k % 3, 50 + 5 * k, -0.06) for k in range(n)], at))
            out.append((f"{material} {n} scale", material, [("scale", 0, 36, -0.25)] * n, at))
            out.append((f"{material} {n} extreme", material, [("to", k % 3, 60 + 6 * k, 0.0) for k in range(n)], at))
    return out


def paper_fit(base, curves, blend_width):
    _, _, M, E = score_grid(base.eta_i_range)
    target = edited_target(base, curves, M, E, blend_width)
    result = fit_coefficients(target.reshape(-1, 3), M.ravel(), E.ravel(), base.eta_i_range, 2, "rgb")
    return result.coefficients_float16


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--quick", action="store_true", help="every fourth edit")
    parser.add_argument("--edits", help="comma-separated edit labels (e.g. 'Cu 4 scale'): only those, not recorded")
    args = parser.parse_args()
    settings = CurveFitSettings()
    cases = edits()[:: 4 if args.quick else 1]
    if args.edits:
        wanted = set(args.edits.split(","))
        cases = [case for case in cases if case[0] in wanted]
    load_at_start = load_average()
    print(
        f"{'edit':<18} {'default dE':>10} {'paper dE':>9} {'default max':>11} {'paper max':>9}"
        f" {'at (deg, eta)':>14} {'range':>15} {'paper range':>15} {'kept':>7} {'ms':>6}"
    )
    rows = []
    for label, material, specs, at in cases:
        base = curve_base_from_nk(library_material(material), (1.0, 2.5))
        curves = [edit_curve(base, e, *spec) for e, spec in zip(at, specs)]
        t0 = time.perf_counter()
        result = fit_curves(curves, base)
        ms = 1e3 * (time.perf_counter() - t0)
        ours = result.metrics["target"]
        P = paper_fit(base, curves, settings.blend_width)
        paper = whole_target_error(base, curves, P, settings.blend_width)
        reflectance = proven_in_range(P, base.eta_i_range)
        rows.append(
            {
                "edit": label,
                "mean": ours["delta_E_mean"],
                "max": ours["delta_E_max"],
                "paper_mean": paper["delta_E_mean"],
                "paper_max": paper["delta_E_max"],
                "paper_is_reflectance": reflectance,
                "kept": result.metrics["objective"],
                "ms": ms,
            }
        )
        print(
            f"{label:<18} {ours['delta_E_mean']:>10.3f} {paper['delta_E_mean']:>9.3f}"
            f" {ours['delta_E_max']:>11.2f} {paper['delta_E_max']:>9.2f}"
            f" {ours['at_theta_deg']:>7.0f}, {ours['at_eta_i']:.2f}"
            f" [{ours['model_min']:.3f}, {ours['model_max']:.3f}]"
            f" [{paper['model_min']:.3f}, {paper['model_max']:.3f}]{'' if reflectance else '*'}"
            f" {result.metrics['objective']:>7} {ms:>6.0f}"
        )
    worse_mean = [r for r in rows if r["mean"] > r["paper_mean"] + 1e-9]
    worse_max = [r for r in rows if r["max"] > r["paper_max"] + 1e-9]
    figures = {
        "edits": len(rows),
        "worse_mean": len(worse_mean),
        "worse_max": len(worse_max),
        "worse_mean_paper_reflectance": sum(r["paper_is_reflectance"] for r in worse_mean),
        "worse_max_paper_reflectance": sum(r["paper_is_reflectance"] for r in worse_max),
        "paper_not_reflectance": sum(not r["paper_is_reflectance"] for r in rows),
        "no_worse_on_both_where_paper_is_reflectance": sum(
            r["mean"] <= r["paper_mean"] + 1e-9 and r["max"] <= r["paper_max"] + 1e-9
            for r in rows
            if r["paper_is_reflectance"]
        ),
        "paper_is_reflectance": sum(r["paper_is_reflectance"] for r in rows),
    }
    print(
        f"\n{len(rows)} edits (* the paper's fit leaves [0, 1] on {figures['paper_not_reflectance']}); "
        f"default worse than the paper's method on the mean on {len(worse_mean)} "
        f"({figures['worse_mean_paper_reflectance']} where the paper's fit is a reflectance), "
        f"on the max on {len(worse_max)} ({figures['worse_max_paper_reflectance']})"
    )
    if args.edits:
        return
    print(
        "recorded:",
        write_result("curve_edits_vs_paper" + ("_quick" if args.quick else ""), figures, load_at_start, rows=rows),
    )


if __name__ == "__main__":
    main()
