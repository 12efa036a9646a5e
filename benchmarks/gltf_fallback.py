"""
The glTF fallback: seen fidelity at roughness 0 and 0.3, and the coat it keeps
==============================================================================

What a viewer without ``EXT_materials_coated_conductor`` draws of the glTF
export (three.js's ``MeshPhysicalMaterial`` with ``KHR_materials_clearcoat``,
the numpy mirror :func:`fitting.exports.tool_layering.three_clearcoat`),
against the coated metal seen from air, over the 22 library conductors at
eta_i 1.33, 1.5 and 2.0, a smooth coat, the metal at roughness 0 (the
spectral stack) and at 0.3 (:func:`fitting.exports.gltf_fallback.rough_seen_ACEScg`).
Four fits of the same values (base colour, ``clearcoatFactor``):

-   ``before``: fitted at roughness 0, factor free in [0, 1] (an earlier
    export, for every roughness);
-   ``after_smooth``: fitted at roughness 0, factor 1, the coat's weight
    which ``EXT_materials_coated_conductor`` composes with (what the export
    writes for a smooth metal; against ``before`` at roughness 0: the cost of
    one coat for both kinds of viewer);
-   ``rough_free``: fitted at roughness 0.3, factor free (the rough fit alone);
-   ``after_rough``: fitted at roughness 0.3, factor 1 (what the export
    writes for a metal of roughness 0.3).

(``after_*``: least squares, then the least mean Delta E,
:func:`fitting.exports.gltf_fallback.mean_refined_base_colour`; ``before`` and
``rough_free``: least squares alone, as the earlier export.)
Each scored at both roughnesses: mean and max Delta E 2000 over the view
angles 0 to 83 degrees and every metal and index (and per index), the least
``clearcoatFactor`` where the coat reflects 2 % or more at normal incidence
(eta_i >= 1.33), and the CPU time of the glTF fit
per export (median over the points; the rough target included).

And what no fallback drawn by three can beat at roughness 0.3
(:func:`fitting.exports.gltf_fallback.viewer_optimum`: the least mean
Delta E of three's ``MeshPhysicalMaterial`` under a white sky, several
starts, per point):

-   ``viewer_optimum``: every glTF value that bears on it free in its range
    (base colour, ``metallicFactor``, ``roughnessFactor``,
    ``KHR_materials_specular`` with ``KHR_materials_ior``,
    ``KHR_materials_clearcoat`` factor and roughness);
-   ``viewer_optimum_coated``: the same with the material's roughness
    (0.3), a smooth coat and ``clearcoatFactor`` at least 0.5 (a coated
    metal of that roughness, as the issue's rule asks of the fallback).

    .venv/bin/python benchmarks/gltf_fallback.py [--materials Cu,Au]

Records benchmarks/results/gltf_fallback.json.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.exports import export_values  # noqa: E402
from fitting.exports.gltf_fallback import (  # noqa: E402
    VISIBLE_COAT_F0,
    coat_F0,
    gltf_seen_delta_E,
    rough_seen_ACEScg,
    viewer_optimum,
)
from fitting.exports.seen_fit import fit_tool_values  # noqa: E402
from fitting.optics.library import LIBRARY_NAMES, library_material  # noqa: E402

ETAS = (1.33, 1.5, 2.0)
ROUGHNESS = 0.3
OPTIMA = {  # name: the values held (name -> bounds), the rest free in their glTF ranges; the first a start of the second
    "viewer_optimum_coated": {
        "roughness": (ROUGHNESS, ROUGHNESS),
        "clearcoat": (0.5, 1.0),
        "clearcoat_roughness": (0.0, 0.0),
    },
    "viewer_optimum": {},
}
VARIANTS = {  # name: (fitted at the metal's roughness, the coat kept)
    "before": (False, False),
    "after_smooth": (False, True),
    "rough_free": (True, False),
    "after_rough": (True, True),
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/gltf_fallback.py")
    parser.add_argument("--materials", default=",".join(LIBRARY_NAMES))
    parser.add_argument("--no-record", action="store_true")
    parser.add_argument("--starts", type=int, default=3, help="starts of each viewer optimum")
    args = parser.parse_args(argv)
    started, load = time.time(), load_average()
    names = args.materials.split(",")
    dE = {v: {r: {eta: [] for eta in ETAS} for r in ("0", "0_3")} for v in VARIANTS}
    factors = {v: [] for v in VARIANTS}
    seconds = {"before": [], "after_rough": []}
    optima = {k: {eta: [] for eta in ETAS} for k in OPTIMA}
    optimum_values = {k: [] for k in OPTIMA}
    for name in names:
        nk = library_material(name)
        for eta in ETAS:
            v = export_values(nk, eta, roughness=ROUGHNESS, coat_roughness=0.0, tools=())
            for variant, (rough, keep) in VARIANTS.items():
                t = time.process_time()
                target = (
                    rough_seen_ACEScg(v.view_cos, eta, v.seen_ACEScg, v.cos_theta, v.target_ACEScg, ROUGHNESS)
                    if rough
                    else None
                )
                fit = fit_tool_values(
                    "gltf",
                    v.view_cos,
                    eta,
                    v.seen_ACEScg,
                    True,
                    roughness=ROUGHNESS if rough else 0.0,
                    rough_target_ACEScg=target,
                    keep_coat=keep,
                )
                if variant in seconds:
                    seconds[variant].append(time.process_time() - t)
                if target is None:
                    target = rough_seen_ACEScg(v.view_cos, eta, v.seen_ACEScg, v.cos_theta, v.target_ACEScg, ROUGHNESS)
                dE[variant]["0"][eta].append(gltf_seen_delta_E(fit, v.view_cos, eta, v.seen_ACEScg))
                dE[variant]["0_3"][eta].append(gltf_seen_delta_E(fit, v.view_cos, eta, target, ROUGHNESS))
                if coat_F0(eta) >= VISIBLE_COAT_F0 - 1e-12:
                    factors[variant].append(float(fit["clearcoat"]))
            start = fit["base_color"]  # after_rough's, the last variant
            for k, held in OPTIMA.items():  # the coated optimum a start of the free one
                also = tuple(optimum_values[o][-1] for o in OPTIMA if o != k and optimum_values[o])
                values, d = viewer_optimum(
                    v.view_cos, target, start, ROUGHNESS, starts=args.starts, fixed=held, also_from=also
                )
                optima[k][eta].append(d)
                optimum_values[k].append(values)
            row = "  ".join(
                f"{k} {dE[k]['0'][eta][-1].mean():.3f}/{dE[k]['0_3'][eta][-1].mean():.3f}" for k in VARIANTS
            )
            row += "  " + "  ".join(f"{k} {optima[k][eta][-1].mean():.3f}" for k in OPTIMA)
            print(f"{name} eta_i {eta:g} (mean at roughness 0/0.3): {row}", flush=True)
    figures: dict = {}
    for variant in VARIANTS:
        figures[variant] = {}
        for r in ("0", "0_3"):
            every = np.concatenate([np.concatenate(dE[variant][r][eta]) for eta in ETAS])
            per_point = [float(d.mean()) for eta in ETAS for d in dE[variant][r][eta]]
            figures[variant][f"roughness_{r}"] = {
                "delta_E_mean": float(every.mean()),
                "delta_E_max": float(every.max()),
                "worst_point_mean": max(per_point),
                "by_eta": {
                    "eta_i_" + f"{eta:g}".replace(".", "_"): {
                        "delta_E_mean": float(np.concatenate(dE[variant][r][eta]).mean()),
                        "delta_E_max": float(np.concatenate(dE[variant][r][eta]).max()),
                    }
                    for eta in ETAS
                },
            }
        figures[variant]["least_clearcoat_where_visible"] = min(factors[variant]) if factors[variant] else None
    for variant in seconds:
        figures[variant]["fit_cpu_ms_median"] = 1e3 * float(np.median(seconds[variant]))
        figures[variant]["fit_cpu_ms_max"] = 1e3 * float(np.max(seconds[variant]))
    for k in OPTIMA:
        every = np.concatenate([np.concatenate(optima[k][eta]) for eta in ETAS])
        figures[k] = {
            "roughness_0_3": {
                "delta_E_mean": float(every.mean()),
                "delta_E_max": float(every.max()),
                "worst_point_mean": max(float(d.mean()) for eta in ETAS for d in optima[k][eta]),
                "by_eta": {
                    "eta_i_" + f"{eta:g}".replace(".", "_"): {
                        "delta_E_mean": float(np.concatenate(optima[k][eta]).mean()),
                        "delta_E_max": float(np.concatenate(optima[k][eta]).max()),
                    }
                    for eta in ETAS
                },
            },
            "values_median": {
                name: float(np.median([np.mean(vals[name]) for vals in optimum_values[k]]))
                for name in ("metallic", "specular", "roughness", "clearcoat", "clearcoat_roughness")
            },
            "points_metallic_below_half": int(sum(vals["metallic"] < 0.5 for vals in optimum_values[k])),
            "points_clearcoat_below_half": int(sum(vals["clearcoat"] < 0.5 for vals in optimum_values[k])),
        }
    after, before = figures["after_rough"], figures["before"]
    figures["done"] = {
        "rough_mean_after_le_smooth_mean_before": after["roughness_0_3"]["delta_E_mean"]
        <= before["roughness_0"]["delta_E_mean"],
        "clearcoat_kept": min(
            figures[k]["least_clearcoat_where_visible"] or 1.0 for k in ("after_smooth", "after_rough")
        )
        >= 0.5,
        "reachable_by_three_at_all": figures["viewer_optimum"]["roughness_0_3"]["delta_E_mean"]
        <= before["roughness_0"]["delta_E_mean"],
        "reachable_as_a_coated_metal": figures["viewer_optimum_coated"]["roughness_0_3"]["delta_E_mean"]
        <= before["roughness_0"]["delta_E_mean"],
    }
    for variant in VARIANTS:
        f = figures[variant]
        print(
            f"{variant}: roughness 0 mean {f['roughness_0']['delta_E_mean']:.3f} max "
            f"{f['roughness_0']['delta_E_max']:.2f}; roughness 0.3 mean {f['roughness_0_3']['delta_E_mean']:.3f}"
            f" max {f['roughness_0_3']['delta_E_max']:.2f}; least clearcoat {f['least_clearcoat_where_visible']}"
        )
    for k in OPTIMA:
        f = figures[k]["roughness_0_3"]
        print(
            f"{k}: roughness 0.3 mean {f['delta_E_mean']:.3f} max {f['delta_E_max']:.2f}", figures[k]["values_median"]
        )
    print({k: (round(figures[k]["fit_cpu_ms_median"], 1), round(figures[k]["fit_cpu_ms_max"], 1)) for k in seconds})
    print(figures["done"])
    elapsed = time.time() - started
    if not args.no_record:
        write_result(
            "gltf_fallback",
            figures,
            load,
            materials=names,
            eta_i=list(ETAS),
            roughness=ROUGHNESS,
            coat_roughness=0.0,
            coat_F0=[round(coat_F0(e), 4) for e in ETAS],
            optimum_starts=args.starts,
            seconds=round(elapsed, 1),
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
