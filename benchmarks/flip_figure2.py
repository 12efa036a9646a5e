"""
The paper's Figure 2 cases: Cr, Ta and Co at eta_i 1.5 and 2.5 under the
white sky. For each, the model and adjusted Lazanyi are compared with the
spectral reference of the same view (per pixel, fitting.colour.reference): mean
FLIP and mean Delta E 2000 over the sphere. Writes the split views (model |
Lazanyi, model | reference) and the FLIP maps to docs/images/.

Records the rows and the range of each column over the six cases in
benchmarks/results/flip_figure2.json (:mod:`benchmarks.record`).

    .venv/bin/python benchmarks/flip_figure2.py [--size 256] [--images DIR]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.fits.material import fit_material
from fitting.optics.library import library_material
from preview_shaders.display import encode_png, false_colour  # noqa: E402
from preview_shaders.preview import PreviewRenderer, difference_maps  # noqa: E402

MATERIALS = ("Cr", "Ta", "Co")
ETA_I = (1.5, 2.5)


def _png(path: Path, image_uint8) -> None:
    path.write_bytes(encode_png(image_uint8))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--images", type=Path, default=ROOT / "docs" / "images")
    args = parser.parse_args()
    load_at_start = load_average()
    args.images.mkdir(parents=True, exist_ok=True)
    rows = []
    with PreviewRenderer() as renderer:
        for name in MATERIALS:
            nk = library_material(name)
            packed = fit_material(nk).packed
            for eta_i in ETA_I:
                ref = renderer.render_preview(packed, nk, eta_i, args.size, "reference")
                laz = renderer.render_preview(packed, nk, eta_i, args.size, "lazanyi")
                _, laz_dE, laz_flip_map, laz_flip = difference_maps(laz.comparison, ref.comparison, ref.mask)
                stem = f"shader_fig2_{name}_{eta_i:g}"
                (args.images / f"{stem}_model_lazanyi.png").write_bytes(laz.png)
                (args.images / f"{stem}_model_reference.png").write_bytes(ref.png)
                # FLIP maps side by side: model vs reference | Lazanyi vs reference.
                both = np.concatenate([ref.flip, laz_flip_map], axis=1)
                _png(args.images / f"{stem}_flip.png", false_colour(both, 1.0, "magma"))
                rows.append((name, eta_i, ref.flip_mean, laz_flip, ref.delta_E_mean, laz_dE))
    print(f"{args.size} x {args.size}, white sky, means over the sphere's pixels\n")
    print("| material | eta_i | FLIP model | FLIP adj. Lazanyi | dE2000 model | dE2000 adj. Lazanyi |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, eta_i, flip_m, flip_l, de_m, de_l in rows:
        print(f"| {name} | {eta_i:g} | {flip_m:.4f} | {flip_l:.4f} | {de_m:.3f} | {de_l:.3f} |")
    keys = ("flip_model", "flip_lazanyi", "delta_E_model", "delta_E_lazanyi")
    cases = [{"material": name, "eta_i": eta_i, **dict(zip(keys, map(float, values)))} for name, eta_i, *values in rows]
    figures = {
        "size": args.size,
        "cases": cases,
        "range": {key: {"min": min(c[key] for c in cases), "max": max(c[key] for c in cases)} for key in keys},
        # How many times closer to the reference the model is than adjusted Lazanyi, in FLIP.
        "flip_lazanyi_over_model": {
            "min": min(c["flip_lazanyi"] / c["flip_model"] for c in cases),
            "max": max(c["flip_lazanyi"] / c["flip_model"] for c in cases),
        },
    }
    print(f"\nwrote {write_result('flip_figure2', figures, load_at_start)}")


if __name__ == "__main__":
    main()
