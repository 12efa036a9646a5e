"""
Rough spheres: the model against the spectral reference, beside adjusted
Lazanyi. Cr, Ta and Co at eta_i 1.5 and 2.5, roughness 0.3 and 0.6, immersed
set-up, white D60 environment, orthographic sphere filling the frame.

-   reference: Mitsuba 3 ``scalar_spectral`` ``roughconductor`` (GGX,
    separable Smith) with n/eta_i, k/eta_i, XYZ film to ACEScg
    (fitting.shading.spectral_render), ``--spp`` samples per pixel;
-   model and adjusted Lazanyi: the project's Monte Carlo of the same BRDF
    (GGX, separable Smith, as Mitsuba) with their Fresnel at VdotH;
-   noise floor: the project's Monte Carlo with the exact spectral Fresnel
    against the same Mitsuba image (what the reference's own noise costs).

Means of FLIP (flip-evaluator, LDR, sRGB-encoded float32 in [0, 1]) and
Delta E 2000 over the sphere's pixels with NdotV >= 0.2 (the rim's pixels
straddle the sphere and the background). Writes
docs/images/rough_<material>_<eta_i>_<roughness>.png (model | reference |
adjusted Lazanyi) and prints the table of docs/shading.md.

    .venv/bin/python benchmarks/rough_spheres.py [--size 64] [--spp 512]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from fitting.fits.material import fit_material
from fitting.models.baselines import baseline_inputs, lazanyi_adjusted
from fitting.models.coated_conductor import collapse_to_eta_i
from fitting.optics.library import library_material
from fitting.shading.microfacet import model_fresnel
from fitting.shading.monte_carlo import rough_sphere_image, spectral_fresnel
from fitting.shading.spectral_render import mitsuba_rough_sphere
from preview_shaders.display import ACEScg_to_sRGB, encode_png, to_uint8
from preview_shaders.preview import difference_maps

ROOT = Path(__file__).resolve().parents[1]
MATERIALS = ("Cr", "Ta", "Co")
ETA_I = (1.5, 2.5)
ROUGHNESS = (0.3, 0.6)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--spp", type=int, default=512)
    parser.add_argument("--samples", type=int, default=16384, help="MC draws per NdotV node")
    parser.add_argument("--images", type=Path, default=ROOT / "docs" / "images")
    args = parser.parse_args()
    args.images.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rows = []
    for name in MATERIALS:
        nk = library_material(name)
        packed = fit_material(nk).packed
        air = baseline_inputs(nk)
        for eta_i in ETA_I:
            F0, a, alpha = collapse_to_eta_i(packed.coefficients.astype(np.float64), eta_i, packed.eta_i_range)[..., 0]
            fresnels = {
                "model": model_fresnel(F0, a, alpha),
                "lazanyi": lambda x, e=eta_i: lazanyi_adjusted(x, e, air["F0_air"], air["F82_air"]),
                "spectral": spectral_fresnel(nk, eta_i),
            }
            for r in ROUGHNESS:
                reference, mask, mu = mitsuba_rough_sphere(nk, eta_i, r, args.size, args.spp, seed=1)
                scored = mask & (mu >= 0.2)
                images, row = {}, [name, eta_i, r]
                for key, fresnel in fresnels.items():
                    images[key], _ = rough_sphere_image(
                        args.size, r, fresnel, samples=args.samples, masking="separable", NdotV_bins=128
                    )
                    _, dE, _, flip = difference_maps(images[key], reference, scored)
                    row += [flip, dE]
                strip = np.concatenate([images["model"], reference, images["lazanyi"]], axis=1)
                png = encode_png(to_uint8(ACEScg_to_sRGB(np.where(np.tile(mask, 3)[..., None], strip, 0.0))))
                (args.images / f"rough_{name}_{eta_i:g}_{r:g}.png").write_bytes(png)
                rows.append(row)
    print(
        f"{args.size} x {args.size} px, Mitsuba {args.spp} spp, MC {args.samples} draws per NdotV; "
        f"means over the sphere's pixels with NdotV >= 0.2 ({time.perf_counter() - t0:.0f} s)\n"
    )
    print(
        "| material | eta_i | roughness | FLIP model | FLIP adj. Lazanyi | dE2000 model | "
        "dE2000 adj. Lazanyi | noise floor FLIP | noise floor dE2000 |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, eta_i, r, fm, dm, fl, dl, fs, ds in rows:
        print(f"| {name} | {eta_i:g} | {r:g} | {fm:.4f} | {fl:.4f} | {dm:.3f} | {dl:.3f} | {fs:.4f} | {ds:.3f} |")


if __name__ == "__main__":
    main()
