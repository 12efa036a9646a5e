"""
Metals from F0 and F82 tint, and the remap under a coat
=======================================================

For every conductor of the library (the batch's 22), its F0 and F82 tint in
air (least squares to the 1 nm spectral reference in air, linear Rec.709,
:func:`fitting.exports.seen_fit.fit_channel_f82`), then:

-   ``inversion``: the exact conductor of :func:`fitting.optics.edge_tint.nk_from_F0_F82`
    against the F82-tint curve it came from, and against the reference in
    air, Delta E 2000 over cos theta in [0, 1] (100 samples); the anchors'
    residual (F0 and F82 tint of the inverted index, largest |difference|).
-   ``under_coat``: at coat index 1.33, 1.5 and 2.0, what an F82-tint
    renderer shows under its coat (the coat's Fresnel reflection plus the
    base at the view angle in air times what the coat lets through, Cycles'
    Principled coat, :func:`fitting.exports.seen_fit.layer_only` ``blender``)
    against the coated metal seen from air (:func:`fitting.colour.seen.seen_ACEScg`),
    Delta E 2000 over 0-83 degrees, for each convention of the base:

    -   ``exact_air``: the exact Fresnel of the metal's index in air (n, k
        fitted per channel in air);
    -   ``f82_air``: F82 tint with the F0 and tint in air (every real-time
        convention today);
    -   ``schlick_air``: Schlick with F0 in air (glTF, three.js);
    -   ``filament_remap``: Schlick with Filament's / HDRP's
        ``f0ClearCoatToSurface`` of that F0;
    -   ``relative_index``: F82 tint with the F0 and tint of the relative
        index (n + i k) / eta_i of the inverted index (the metal's F0 and F82
        re-derived at the coat index, at the same angle);
    -   ``remap``: F82 tint with :func:`fitting.optics.edge_tint.F0_F82_under_coat`.

    .venv/bin/python benchmarks/edge_tint.py [--materials Au,Cu]

Records benchmarks/results/edge_tint.json: per convention and coat index the
mean and the max over the conductors of each one's mean Delta E, and the
worst single angle; the inversion's mean and max.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.colour.delta_e import delta_E_map  # noqa: E402
from fitting.colour.reference import reference_ACEScg  # noqa: E402
from fitting.colour.seen import SEEN_ANGLES_DEG, seen_ACEScg  # noqa: E402
from fitting.exports.colour_space import ACEScg_to_lin_rec709, lin_rec709_to_ACEScg  # noqa: E402
from fitting.exports.seen_fit import (  # noqa: E402
    fit_channel_conductor,
    fit_channel_f82,
    fit_channel_schlick,
    layer_only,
)
from fitting.exports.tool_fresnel import f82_tint, schlick  # noqa: E402
from fitting.optics.edge_tint import F0_F82_from_nk, F0_F82_under_coat, nk_from_F0_F82  # noqa: E402
from fitting.optics.fresnel import fresnel_conductor  # noqa: E402
from fitting.optics.library import LIBRARY_NAMES, library_material  # noqa: E402

ETAS = (1.33, 1.5, 2.0)
CONVENTIONS = ("exact_air", "f82_air", "schlick_air", "filament_remap", "relative_index", "remap")


def filament_f0(f0):
    """Filament's ``f0ClearCoatToSurface`` (and HDRP's): F0 under a coat of 1.5, fitted polynomial."""
    return np.clip(f0 * (f0 * (0.941892 - 0.263008 * f0) + 0.346479) - 0.0285998, 0.0, 1.0)


def _index(F0, tint):
    index = nk_from_F0_F82(F0, tint)
    return index.n, index.k


def bases(view, eta, air):
    """The base's response at the view cosines in air, (S, 3) linear Rec.709, per convention."""
    F0, tint, n, k, F0s = air
    rF0, rtint = F0_F82_under_coat(F0, tint, eta)
    return {
        "exact_air": np.stack([fresnel_conductor(view, 1.0, n[c], k[c]) for c in range(3)], axis=-1),
        "f82_air": f82_tint(view, F0, tint),
        "schlick_air": schlick(view, F0s),
        "filament_remap": schlick(view, filament_f0(F0s)),
        "relative_index": f82_tint(view, *(np.clip(v, 0.0, 1.0) for v in F0_F82_from_nk(*_index(F0, tint), eta))),
        "remap": f82_tint(view, rF0, rtint),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/edge_tint.py")
    parser.add_argument("--materials", default=",".join(LIBRARY_NAMES))
    args = parser.parse_args(argv)
    load = load_average()
    mu = np.linspace(0.0, 1.0, 100)
    view = np.cos(np.radians(SEEN_ANGLES_DEG))
    rows, inversion = {}, {}
    for name in args.materials.split(","):
        nk = library_material(name)
        air_rec709 = ACEScg_to_lin_rec709(reference_ACEScg(nk, mu, 1.0, 1.0))
        F0, tint = fit_channel_f82(mu, air_rec709)
        n, k = fit_channel_conductor(mu, air_rec709)
        air = (F0, tint, n, k, fit_channel_schlick(mu, air_rec709))
        index = nk_from_F0_F82(F0, tint)
        exact = np.stack([fresnel_conductor(mu, 1.0, index.n[c], index.k[c]) for c in range(3)], axis=-1)
        back_F0, back_tint = F0_F82_from_nk(index.n, index.k)
        inversion[name] = {
            "vs_f82_curve": float(
                delta_E_map(lin_rec709_to_ACEScg(f82_tint(mu, F0, tint)), lin_rec709_to_ACEScg(exact)).mean()
            ),
            "vs_reference": float(delta_E_map(lin_rec709_to_ACEScg(air_rec709), lin_rec709_to_ACEScg(exact)).mean()),
            "anchor_residual": float(
                max(np.max(np.abs(back_F0 - F0)), np.max(np.abs(back_tint - tint) * index.reachable))
            ),
            "reachable": bool(index.reachable.all()),
        }
        for eta in ETAS:
            seen = seen_ACEScg(nk, view, eta)
            for convention, base in bases(view, eta, air).items():
                layered = layer_only("blender", view, eta, base)
                dE = delta_E_map(seen, lin_rec709_to_ACEScg(layered))
                rows.setdefault(f"eta_i_{eta:g}".replace(".", "_"), {}).setdefault(convention, {})[name] = [
                    float(dE.mean()),
                    float(dE.max()),
                ]
        print(name, {c: round(rows["eta_i_1_5"][c][name][0], 3) for c in CONVENTIONS}, flush=True)
    figures = {
        "inversion": {
            key: {
                "mean": round(float(np.mean([r[key] for r in inversion.values()])), 4),
                "max": round(float(np.max([r[key] for r in inversion.values()])), 4),
            }
            for key in ("vs_f82_curve", "vs_reference", "anchor_residual")
        }
    }
    figures["inversion"]["unreachable"] = sorted(m for m, r in inversion.items() if not r["reachable"])
    for eta_key, by_convention in rows.items():
        figures[eta_key] = {}
        for convention in CONVENTIONS:
            means = np.array([v[0] for v in by_convention[convention].values()])
            maxima = np.array([v[1] for v in by_convention[convention].values()])
            worst = max(by_convention[convention], key=lambda m: by_convention[convention][m][0])
            figures[eta_key][convention] = {
                "mean": round(float(means.mean()), 3),
                "max_of_means": round(float(means.max()), 3),
                "worst": worst,
                "max_angle": round(float(maxima.max()), 2),
            }
        remap = np.array([v[0] for v in by_convention["remap"].values()])
        filament = np.array([v[0] for v in by_convention["filament_remap"].values()])
        nothing = np.array([v[0] for v in by_convention["f82_air"].values()])
        figures[eta_key]["filament_worse_than_nothing"] = int(np.sum(filament > nothing))
        figures[eta_key]["remap_worse_than_nothing"] = int(np.sum(remap > nothing))
    for key, value in figures.items():
        print(key, value)
    path = write_result(
        "edge_tint", figures, load, materials=args.materials.split(","), rows=rows, inversion_rows=inversion
    )
    print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
