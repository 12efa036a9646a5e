"""
The approximate coated split sum (fitting.shading.ibl.split_sum_coated)
against the coated Monte Carlo (fitting.shading.monte_carlo, 16,384 draws per
NdotV, seed 0), coat roughness 0.1, NdotV 0.05, 0.2, 0.5, 0.8, 1: the largest
over- and under-estimate per material, eta_i and roughness.

    .venv/bin/python benchmarks/coated_split_sum.py
"""

from __future__ import annotations

import numpy as np

from fitting.fits.material import fit_material
from fitting.models.coated_conductor import collapse_to_eta_i
from fitting.optics.library import library_material
from fitting.shading.ibl import split_sum_coated
from fitting.shading.microfacet import model_fresnel
from fitting.shading.monte_carlo import directional_albedo

NDOTV = np.array([0.05, 0.2, 0.5, 0.8, 1.0])


def main() -> None:
    print("| material | eta_i | roughness | worst over | worst under |")
    print("|---|---:|---:|---:|---:|")
    for name in ("Cr", "Au"):
        packed = fit_material(library_material(name)).packed
        for eta_i in (1.5, 2.5):
            F0, a, alpha = collapse_to_eta_i(packed.coefficients.astype(np.float64), eta_i, packed.eta_i_range)[..., 0]
            for r in (0.05, 0.3, 0.6):
                mc = directional_albedo(NDOTV, r, model_fresnel(F0, a, alpha), "coated", eta_i, 0.1, samples=16384)
                error = split_sum_coated(NDOTV, r, F0, a, alpha, eta_i, 0.1) / mc.mean - 1.0
                print(f"| {name} | {eta_i:g} | {r:g} | {100 * error.max():+.1f} % | {100 * error.min():+.1f} % |")


if __name__ == "__main__":
    main()
