"""
Exports: how much each tool loses under a coat
==============================================

For each conductor of the library and each coating index, the Delta E 2000
(mean over 100 values of cos theta in the coating, evenly over [0, 1])
between the spectral reference under the coat (1 nm, linear ACEScg) and the
base Fresnel of each export as its tool evaluates it
(:mod:`fitting.exports.tool_fresnel`):

-   ``mtlx`` (and Blender's Metallic BSDF, Physical Conductor): exact conductor
    Fresnel of the per-channel relative index, fitted in linear Rec.709;
-   ``openpbr`` (and Blender's Principled BSDF): the F82-tint model with F0 and
    tint fitted under the coat, both in [0, 1];
-   ``gltf``: Schlick with the fitted F0;
-   for comparison, the air-fitted ACEScg per-channel index of
    :func:`fitting.fits.rgb_conductor.rgb_nk` divided by eta_i, in a renderer working
    in ACEScg (``rgb_nk ACEScg``) and pasted into a Rec.709 tool unchanged
    (``rgb_nk as 709``).

    .venv/bin/python benchmarks/exports_fidelity.py [--eta-i 1.5,1.33,2.0] [--materials Au,Cu]

Prints one table per eta_i (Markdown) and the mean row; records each eta_i's
mean and max row and every material's row in
benchmarks/results/exports_fidelity.json (:mod:`benchmarks.record`), keyed
by ``eta_i_1_5`` for eta_i = 1.5 (a dot would split a figure's path), the
columns by ``mtlx``, ``openpbr``, ``gltf``, ``rgb_nk_ACEScg``, ``rgb_nk_as_709``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.exports import export_fidelity, export_values  # noqa: E402
from fitting.exports.tool_fresnel import mx_fresnel_conductor  # noqa: E402
from fitting.exports.colour_space import lin_rec709_to_ACEScg  # noqa: E402
from fitting.colour.delta_e import delta_E_map  # noqa: E402
from fitting.fits.rgb_conductor import rgb_nk  # noqa: E402
from fitting.optics.library import LIBRARY_NAMES, library_material  # noqa: E402

COLUMNS = ("mtlx / Metallic BSDF", "openpbr / Principled", "gltf", "rgb_nk ACEScg", "rgb_nk as 709")
KEYS = ("mtlx", "openpbr", "gltf", "rgb_nk_ACEScg", "rgb_nk_as_709")
"""The columns' keys in the record."""


def material_row(name: str, eta_i: float, air_nk: tuple) -> list[float]:
    nk = library_material(name)
    values = export_values(nk, eta_i, tools=())  # the naive values only (the seen fits: benchmarks/exports_seen.py)
    row = [export_fidelity(values, target)["delta_E_mean"] for target in ("mtlx", "openpbr", "gltf")]
    n, k = air_nk
    exact = mx_fresnel_conductor(values.cos_theta, n / eta_i, k / eta_i)
    row.append(float(delta_E_map(values.target_ACEScg, exact).mean()))
    row.append(float(delta_E_map(values.target_ACEScg, lin_rec709_to_ACEScg(exact)).mean()))
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/exports_fidelity.py")
    parser.add_argument("--eta-i", default="1.5,1.33,2.0", help="comma-separated coating indices")
    parser.add_argument("--materials", help="comma-separated subset (default: all 22)")
    args = parser.parse_args(argv)
    load_at_start = load_average()
    etas = [float(v) for v in args.eta_i.split(",")]
    figures = {}
    names = args.materials.split(",") if args.materials else list(LIBRARY_NAMES)
    air = {name: rgb_nk(library_material(name)) for name in names}
    for eta_i in etas:
        rows = {name: material_row(name, eta_i, air[name]) for name in names}
        print(f"\neta_i = {eta_i:g}: mean Delta E 2000 under the coat, 100 cos theta, 1 nm reference\n")
        print("| material | " + " | ".join(COLUMNS) + " |")
        print("|---|" + "---:|" * len(COLUMNS))
        for name, row in rows.items():
            print(f"| {name} | " + " | ".join(f"{v:.3f}" for v in row) + " |")
        mean = np.mean(list(rows.values()), axis=0)
        print("| **mean** | " + " | ".join(f"**{v:.3f}**" for v in mean) + " |")
        worst = np.max(list(rows.values()), axis=0)
        print("| max | " + " | ".join(f"{v:.3f}" for v in worst) + " |")
        figures["eta_i_" + f"{eta_i:g}".replace(".", "_")] = {
            "mean": dict(zip(KEYS, map(float, mean))),
            "max": dict(zip(KEYS, map(float, worst))),
            "material": {name: dict(zip(KEYS, row)) for name, row in rows.items()},
        }
    print(f"\nwrote {write_result('exports_fidelity', figures, load_at_start)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
