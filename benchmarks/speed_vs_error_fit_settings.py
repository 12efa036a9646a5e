"""
Speed against error: the fitting settings
=========================================

The fitting settings on the fit-time-against-error plane, for
``benchmarks/speed_vs_error.py``: the grid size (cos theta x eta_i samples,
Gauss-Legendre or uniform), the spectral step of the fitting reference and
the objective, in full cross product; for each, the summed fit time of the
22 conductors and their mean float16 Delta E 2000.

-   :func:`fit_settings_table`: the rows, one per setting.
-   :func:`print_fit_settings`: their Markdown table, the front, and the
    figure (``docs/images/speed_vs_error_fit_settings.png``).
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

from benchmarks.speed_vs_error_figures import figure_fit_settings
from benchmarks.speed_vs_error_report import pareto_front
from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import evaluation_grid, reference_ACEScg
from fitting.fits.material import fit_material
from fitting.fits.settings import OBJECTIVES, FitSettings
from fitting.models.coated_conductor import coated_conductor_model
from fitting.optics.library import LIBRARY_NAMES, library_material

__all__ = ["fit_settings_table", "print_fit_settings"]


def fit_settings_table(grid: int) -> list[dict]:
    """Every fitting setting: the 22 conductors' summed fit time and float16 Delta E 2000 on a ``grid`` square."""
    grids = [
        (8, 3, "gauss"),
        (12, 4, "gauss"),
        (16, 6, "gauss"),
        (24, 8, "gauss"),
        (16, 6, "uniform"),
        (24, 7, "uniform"),
    ]
    steps = [1.0, 5.0, 10.0, 20.0]
    references = {}
    M, E = evaluation_grid(grid)
    for name in LIBRARY_NAMES:
        references[name] = reference_ACEScg(library_material(name), M, E)
    rows = []
    for (mu_n, eta_n, kind), step, objective in itertools.product(grids, steps, OBJECTIVES):
        settings = FitSettings(mu_samples=mu_n, eta_samples=eta_n, grid=kind, step_nm=step, objective=objective)
        seconds, errors = 0.0, []
        for name in LIBRARY_NAMES:
            fit = fit_material(library_material(name), settings=settings)
            seconds += fit.timings["total"]
            model = coated_conductor_model(M, E, fit.coefficients_float16)
            errors.append(float(delta_E_map(references[name], model).mean()))
        rows.append(
            {
                "grid": f"{mu_n}x{eta_n} {kind}",
                "step_nm": step,
                "objective": objective,
                "seconds": seconds,
                "mean": float(np.mean(errors)),
                "max_mean": float(np.max(errors)),
                "default": settings == FitSettings(),
            }
        )
    return rows


def _key(row) -> str:
    return f"{row['grid']} {row['step_nm']:g} nm {row['objective']}"


def print_fit_settings(grid: int, images: Path | None) -> None:
    """Print the fitting settings' table (Delta E on a ``grid`` square); with ``images``, write the figure there."""
    fit_rows = fit_settings_table(grid)
    fit_front = pareto_front({_key(r): (r["seconds"], r["mean"]) for r in fit_rows})
    print(f"\n## Fitting settings: fit time against error, {len(LIBRARY_NAMES)} conductors\n")
    print(
        "| grid (cos theta x eta_i) | step (nm) | objective | fit time per conductor (ms) "
        "| mean dE (f16) | worst conductor mean dE | on front |"
    )
    print("|---|---:|---|---:|---:|---:|---|")
    for r in sorted(fit_rows, key=lambda r: r["seconds"]):
        name = _key(r)
        mark = " **(default)**" if r["default"] else ""
        print(
            f"| {r['grid']}{mark} | {r['step_nm']:g} | {r['objective']} | "
            f"{r['seconds'] / len(LIBRARY_NAMES) * 1e3:.1f} | {r['mean']:.4f} | {r['max_mean']:.3f} | "
            f"{'yes' if name in fit_front else ''} |"
        )
    default = next(r for r in fit_rows if r["default"])
    print(f"\nDefault setting ({_key(default)}) on the front: **{'yes' if _key(default) in fit_front else 'no'}**")
    if images is not None:
        figure_fit_settings(images / "speed_vs_error_fit_settings.png", fit_rows, fit_front, _key, len(LIBRARY_NAMES))
        print("\nwrote docs/images/speed_vs_error_fit_settings.png")
