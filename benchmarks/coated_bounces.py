"""
The bounces between a smooth coat and a rough metal: the glTF extension's approximation against a random walk
===========================================================================================================

Under a smooth coat of index eta, light reflected by a rough metal meets the
underside of the coat at every angle: inside the critical angle it leaves
with the coat's transmission and is otherwise reflected back, beyond it it
is totally reflected; either way it reaches the metal again, and so on. The
extension (docs/gltf/EXT_materials_coated_conductor/, the three.js plugin)
draws the metal's lobe through the coat as fitting.shading.coated_layer
says: for a mirror metal the exact series of bounces, for a rough one the
share of the lobe that leaves at once and the rest returned spread over the
hemisphere (total internal reflection included), blended by roughness.

This benchmark measures that approximation against a random walk of the
same layer (unpolarised on both sides, so that only the bounces differ):
eye paths enter the coat at mu (weight 1 - F_d(mu)), are reflected by the
metal's GGX lobe (visible normals, Heitz 2018, weight F(v.h) G2/G1, the
single-scattering microfacet lobe the extension uses), escape through the
coat with 1 - F_d at their angle (0 beyond the critical angle) and go on
with the rest, for :data:`BOUNCES` bounces. The metal's Fresnel is its 1 nm
spectral reference under the coat in ACEScg, per channel. The white sky's
radiance: F_d(mu) + the base; Delta E 2000 of the extension's series and of
the first bounce alone (no series, the extension before the bounces) against
the walk (``layer``: the extension's; ``series``: the mirror's series with
the rough albedo, which ignores that the rough lobe leaves partly beyond
the critical angle), over the view cosines of a ball's pixels (mu >= 0.1, as
benchmarks/three_parity.py). At roughness 0.02 the walk must give the
mirror's series itself (a check of the walk, recorded as ``check``)::

    .venv/bin/python benchmarks/coated_bounces.py
    .venv/bin/python benchmarks/coated_bounces.py --materials Au --record -
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import write_result  # noqa: E402
from fitting.colour.delta_e import delta_E_map  # noqa: E402
from fitting.colour.reference import reference_ACEScg_grid  # noqa: E402
from fitting.optics.coated_stack import refracted_cos  # noqa: E402
from fitting.optics.fresnel import fresnel_dielectric  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from fitting.shading.coated_layer import seen_base  # noqa: E402
from fitting.shading.ibl import directional_albedo  # noqa: E402
from fitting.shading.microfacet import (  # noqa: E402
    alpha_g_from_roughness,
    sample_visible_normal,
    smith_G1,
    smith_G2,
)

BOUNCES = 24
SAMPLES = 3000
# View cosines as a ball's pixels spread them (uniform in NdotV^2), mu >= 0.1.
MU = np.sqrt(np.linspace(0.01, 1.0, 24))
ROUGHNESS = (0.1, 0.3, 0.6)
ETAS = (1.5, 2.0)
_NODES = np.linspace(0.0, 1.0, 257)


def metal_fresnel(nk, eta: float):
    """The metal's 1 nm reference under a coat of ``eta``, ACEScg: cos -> (..., 3), interpolated on 257 nodes."""
    table = reference_ACEScg_grid(nk, _NODES, [eta])[0]
    return lambda c: np.stack([np.interp(np.asarray(c), _NODES, table[:, i]) for i in range(3)], axis=-1)


def walk(fresnel, eta: float, roughness: float, mu: np.ndarray, samples: int, seed: int = 0) -> np.ndarray:
    """The base's share of the white sky's radiance at each ``mu`` by the random walk, (len(mu), 3)."""
    rng = np.random.default_rng(seed)
    alpha = alpha_g_from_roughness(roughness)
    mu_t = refracted_cos(mu, eta)
    # Eye paths inside the coat, pointing away from the metal, at the refracted view cosine.
    w = np.repeat(np.stack([np.sqrt(1.0 - mu_t**2), np.zeros_like(mu_t), mu_t], axis=-1), samples, axis=0)
    weight = np.repeat((1.0 - fresnel_dielectric(mu, 1.0, eta))[:, None], samples, axis=0) * np.ones((1, 3))
    out = np.zeros_like(weight)
    for _ in range(BOUNCES):
        h = sample_visible_normal(w, alpha, rng.random(len(w)), rng.random(len(w)))
        wh = np.sum(w * h, axis=-1)
        l = 2.0 * wh[:, None] * h - w
        G = np.where(l[:, 2] > 0.0, smith_G2(w[:, 2], l[:, 2], alpha) / smith_G1(w[:, 2], alpha), 0.0)
        weight = weight * fresnel(np.clip(wh, 0.0, 1.0)) * G[:, None]
        # At the coat's underside: out with the transmission (0 beyond the critical angle).
        R = fresnel_dielectric(np.clip(l[:, 2], 0.0, 1.0), eta, 1.0)
        out += weight * (1.0 - R)[:, None]
        weight = weight * R[:, None]
        w = np.stack([-l[:, 0], -l[:, 1], l[:, 2]], axis=-1)  # reflected down: the next eye direction
    return out.reshape(len(mu), samples, 3).mean(axis=1)


def series(E: np.ndarray, mu: np.ndarray, eta: float, bounces: bool = True) -> np.ndarray:
    """The extension's base: [1 - F_d]^2 E / (1 - F_d E) (unpolarised), or without the series."""
    Fd = fresnel_dielectric(mu, 1.0, eta)[:, None]
    return (1.0 - Fd) ** 2 * E / ((1.0 - Fd * E) if bounces else 1.0)


def case(nk, eta: float, roughness: float, samples: int) -> dict:
    fresnel = metal_fresnel(nk, eta)
    coat = fresnel_dielectric(MU, 1.0, eta)[:, None]
    E = directional_albedo(refracted_cos(MU, eta), roughness, fresnel)
    truth = coat + walk(fresnel, eta, roughness, MU, samples)
    figures = {}
    variants = [
        ("layer", seen_base(MU, eta, roughness, fresnel)),
        ("series", series(E, MU, eta)),
        ("first_bounce", series(E, MU, eta, bounces=False)),
    ]
    for name, base in variants:
        dE = delta_E_map(truth, coat + base)
        figures[name] = {"mean": float(dE.mean()), "max": float(dE.max())}
    figures["luminance_ratio"] = float(np.mean((coat + variants[0][1])[:, 1] / truth[:, 1]))
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--materials", default="Ag,Al,Au,Cu,Cr,Ni", help="comma-separated library materials")
    parser.add_argument("--samples", type=int, default=SAMPLES, help="paths per view cosine")
    parser.add_argument("--record", default="coated_bounces", help="benchmarks/results/NAME.json ('-': none)")
    args = parser.parse_args()
    started, load = time.perf_counter(), os.getloadavg()[0]
    rows = []
    for material in args.materials.split(","):
        nk = library_material(material)
        for eta in ETAS:
            for roughness in ROUGHNESS:
                f = case(nk, eta, roughness, args.samples)
                rows.append({"material": material, "eta_i": eta, "roughness": roughness, **f})
                print(
                    f"{material} eta {eta} r {roughness}: layer {f['layer']['mean']:.3f} "
                    f"(max {f['layer']['max']:.3f}), series {f['series']['mean']:.3f}, "
                    f"first bounce {f['first_bounce']['mean']:.3f}, "
                    f"luminance ratio {f['luminance_ratio']:.4f}",
                    file=sys.stderr,
                )
    # The walk's check: a near-mirror metal gives the mirror's series.
    nk = library_material("Au")
    fresnel = metal_fresnel(nk, 1.5)
    coat = fresnel_dielectric(MU, 1.0, 1.5)[:, None]
    mirror = coat + series(fresnel(refracted_cos(MU, 1.5)), MU, 1.5)
    check = float(delta_E_map(mirror, coat + walk(fresnel, 1.5, 0.02, MU, 2000)).mean())
    by = {}
    for r in ROUGHNESS:
        of = [row for row in rows if row["roughness"] == r]
        key = f"r{round(100 * r):02d}"  # r10, r30, r60: no dot in a figure's path
        by[key] = {
            name: {
                "mean": float(np.mean([o[name]["mean"] for o in of])),
                "worst_mean": float(max(o[name]["mean"] for o in of)),
                "worst_max": float(max(o[name]["max"] for o in of)),
            }
            for name in ("layer", "series", "first_bounce")
        }
        by[key]["luminance_ratio_min"] = float(min(o["luminance_ratio"] for o in of))
    figures = {"by_roughness": by, "check_mirror_mean": check, "cases": len(rows)}
    print(figures)
    if args.record != "-":
        path = write_result(
            args.record,
            figures,
            load,
            rows=rows,
            samples=args.samples,
            bounces=BOUNCES,
            seconds=round(time.perf_counter() - started),
        )
        print(f"recorded in {path.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
