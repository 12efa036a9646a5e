"""
A scene material over a range: its time against an earlier commit
=================================================================

What one material of a scene costs (:func:`fitting.fits.scene_fit.fit_scene_material`,
eta_i over a range, the degree rule: the general fit, the fits of degree
0, 1 and 2 over the range, each scored on the scene's evaluation grid
against the 1 nm spectral reference), in CPU time with one BLAS thread,
for each library conductor, in a checkout of ``--before`` (by default
09bbd13, the commit before the scene's reference on the product-grid
kernel and the lean trust-region solver) and in this checkout, side by
side (:mod:`benchmarks.side_by_side`: two processes taking turns material
by material, the order swapped every item). Beside the time, the figures
the user gets: the chosen degree and the scene's mean and max Delta E 2000
on both sides, and the largest change between them.

Records benchmarks/results/scene_speed.json (``figures``: the median and
max CPU ms of each side, their ratio, ``reference_ms``: this checkout's
median time of the reference alone, and ``delta_E_change_max``).

``--output NAME`` records benchmarks/results/NAME.json instead
(``scene_speed_uncertainty_kept``: against 80c7dee, before the data's
uncertainty was kept across a scene's fits of one range;
``scene_speed_stages``: against 36bdfd2, before a scene's candidates shared
their reference, only the shipped fit was assessed and a candidate already
worse than the general fit went unguarded).

Usage: python benchmarks/scene_speed.py [--before REV] [--range 1.2:1.8] [--materials Au,Cu] [--output NAME]
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

from benchmarks.export_speed import summary  # noqa: E402
from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.side_by_side import Side, checkout, serve  # noqa: E402

BEFORE = "09bbd13"
"""The last commit whose scenes took their reference sample by sample."""


def child(root: str, names: list[str], lo: float, hi: float) -> int:
    """One side: scene fits of ``root``; each material answered with its CPU ms and figures."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")
    sys.path.insert(0, root)
    from fitting import library_material
    from fitting.colour.reference import reference_ACEScg_grid
    from fitting.fits.scene_fit import fit_scene_material
    from fitting.fits.scene_schema import EtaSpec, SceneMaterial

    spec = EtaSpec("range", (lo, hi))

    def entry(name: str) -> SceneMaterial:
        return SceneMaterial(name, name, library_material(name), spec)

    fit_scene_material(entry("Au"))  # imports and caches

    def answer(name: str) -> dict:
        material = entry(name)
        t = time.process_time()
        result = fit_scene_material(material)
        ms = 1e3 * (time.process_time() - t)
        t = time.process_time()
        reference_ACEScg_grid(material.nk, np.linspace(0.0, 1.0, 100), spec.evaluation_eta_i())
        reference_ms = 1e3 * (time.process_time() - t)
        # The chosen candidate: its kind and degree (an rgb-conductor's pack has no power axis;
        # a checkout before the rule's record, such as 09bbd13, names only its pack's).
        choice = result.choice or {"model": result.packed.model, "degree": result.degree}
        degree = f"{choice['model']} {choice['degree']}"
        return {
            "ms": ms,
            "reference_ms": reference_ms,
            "degree": degree,
            "mean": result.scene.mean,
            "max": result.scene.max,
        }

    return serve(names, answer)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--before", default=BEFORE, help=f"the commit to compare against (default {BEFORE})")
    parser.add_argument("--range", default="1.2:1.8", help="the scene's eta_i range LO:HI (default 1.2:1.8)")
    parser.add_argument("--materials", default=None, help="library conductors (default all)")
    parser.add_argument(
        "--output", default="scene_speed", help="record to write, benchmarks/results/NAME.json (default scene_speed)"
    )
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--items", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    lo, hi = (float(v) for v in args.range.split(":"))
    if args.child:
        return child(args.child, args.items.split(","), lo, hi)
    from fitting import LIBRARY_NAMES

    items = args.materials.split(",") if args.materials else list(LIBRARY_NAMES)
    load_start = load_average()
    answers = {"before": {}, "after": {}}
    with checkout(args.before) as before_root:
        sides = {}
        try:
            common = ("--items", ",".join(items), "--range", args.range)
            sides["before"] = Side(__file__, before_root, *common)
            sides["after"] = Side(__file__, ROOT, *common)
            for i, item in enumerate(items):
                for name in ("before", "after") if i % 2 == 0 else ("after", "before"):
                    answers[name][item] = sides[name].ask(item)
                b, a = answers["before"][item], answers["after"][item]
                print(
                    f"{item:>5} {b['ms']:7.0f} ms -> {a['ms']:5.0f} ms (reference {b['reference_ms']:4.0f} -> "
                    f"{a['reference_ms']:3.0f} ms)  degree {b['degree']}/{a['degree']}  "
                    f"mean {b['mean']:.4f}/{a['mean']:.4f}  load {os.getloadavg()[0]:.2f}",
                    flush=True,
                )
        finally:
            for side in sides.values():
                side.close()
    before = [answers["before"][i]["ms"] for i in items]
    after = [answers["after"][i]["ms"] for i in items]
    figures = {
        "before_commit": args.before,
        "eta_i_range": [lo, hi],
        **summary(before, after),
        "reference_ms": float(np.median([answers["after"][i]["reference_ms"] for i in items])),
        "degrees_changed": sum(answers["before"][i]["degree"] != answers["after"][i]["degree"] for i in items),
        "delta_E_change_max": float(
            max(abs(answers["after"][i][k] - answers["before"][i][k]) for i in items for k in ("mean", "max"))
        ),
    }
    print(
        f"\nmedian {figures['before_median_ms']:.0f} ms -> {figures['after_median_ms']:.0f} ms "
        f"({figures['ratio']:.2f}x); max {figures['before_max_ms']:.0f} -> {figures['after_max_ms']:.0f} ms; "
        f"degrees changed {figures['degrees_changed']}; largest Delta E change {figures['delta_E_change_max']:.2e}"
    )
    print("recorded:", write_result(args.output, figures, load_start, materials=items, runs=answers))
    return 0


if __name__ == "__main__":
    sys.exit(main())
