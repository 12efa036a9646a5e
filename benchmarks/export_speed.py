"""
Export time against an earlier commit, with what the export shows
=================================================================

What a download of an export costs: the CPU time of
:func:`fitting.exports.export_values` (every tool's values fitted to the
coated metal seen from air, :mod:`fitting.exports.seen_fit`; one BLAS
thread) for each library conductor at each ``--eta-i``, in a checkout of
``--before`` (by default 07e8a6c, the commit before the seen fits evaluated
their Jacobian's points at once) and in this checkout, side by side
(:mod:`benchmarks.side_by_side`: two processes taking turns item by item,
the order swapped every item). Beside the time, the accuracy the user gets:
each tool's Delta E 2000 (mean and max over the view angles) of both
sides, the largest change between them, and the largest rise of a mean
and of a max (``delta_E_rise_mean``, ``delta_E_rise_max``: value and where).

Prints a table per coating index and records
benchmarks/results/export_speed.json (``figures``: ``all`` and
``eta_i_1``, ``eta_i_1_5``, ...: the median and max CPU ms of each side
and the ratio of the medians; ``delta_E``: per tool, this checkout's mean
of the means and max of the maxima; ``delta_E_change_max``).

``--output NAME`` records benchmarks/results/NAME.json instead
(``export_speed_numpy_de2000``: the exports against 09bbd13, before the
CIEDE2000 of their residuals was written out in numpy;
``export_speed_jacobians``: against e780278, before the seen fits had exact
Jacobians and least squares on the Delta E's components, at eta_i 1, 1.5, 2;
``export_speed_layer_terms``: against 80c7dee, before the layerings kept
their per-angle terms and glTF's floor bisection its affine terms).

Usage: python benchmarks/export_speed.py [--before REV] [--eta-i 1.0,1.5] [--materials Au,Cu] [--output NAME]
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

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.side_by_side import Side, checkout, serve  # noqa: E402

BEFORE = "07e8a6c"
"""The last commit whose seen fits evaluated their Jacobian one point per call."""


def child(root: str, names: list[str]) -> int:
    """One side: the exports of ``root``; each ``material@eta_i`` answered with its CPU ms and Delta E per tool."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")
    sys.path.insert(0, root)
    from fitting import library_material
    from fitting.exports.seen_fit import seen_fidelity
    from fitting.exports.values import export_values

    export_values(library_material("Au"), 1.5, tools=("gltf",))  # imports and caches

    def answer(item: str) -> dict:
        material, eta = item.split("@")
        nk = library_material(material)
        t = time.process_time()
        values = export_values(nk, float(eta))
        ms = 1e3 * (time.process_time() - t)
        return {"ms": ms, "delta_E": {tool: seen_fidelity(values, tool) for tool in values.tools}}

    return serve(names, answer)


def key(eta: float) -> str:
    return "eta_i_" + f"{eta:g}".replace(".", "_")


def summary(before: list[float], after: list[float]) -> dict:
    """Milliseconds of the same items before and after: medians, their ratio, the worst of each, the count."""
    a, b = np.array(before), np.array(after)
    return {
        "before_median_ms": float(np.median(a)),
        "after_median_ms": float(np.median(b)),
        "ratio": float(np.median(b) / np.median(a)),
        "before_max_ms": float(a.max()),
        "after_max_ms": float(b.max()),
        "items": int(a.size),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--before", default=BEFORE, help=f"the commit to compare against (default {BEFORE})")
    parser.add_argument("--eta-i", default="1.0,1.5", help="coating indices (default 1.0,1.5)")
    parser.add_argument("--materials", default=None, help="library conductors (default all)")
    parser.add_argument(
        "--output", default="export_speed", help="record to write, benchmarks/results/NAME.json (default export_speed)"
    )
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--items", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        return child(args.child, args.items.split(","))
    from fitting import LIBRARY_NAMES

    etas = [float(e) for e in args.eta_i.split(",")]
    materials = args.materials.split(",") if args.materials else list(LIBRARY_NAMES)
    items = [f"{m}@{eta:g}" for eta in etas for m in materials]
    load_start = load_average()
    answers = {"before": {}, "after": {}}
    with checkout(args.before) as before_root:
        sides = {}
        try:
            sides["before"] = Side(__file__, before_root, "--items", ",".join(items))
            sides["after"] = Side(__file__, ROOT, "--items", ",".join(items))
            for i, item in enumerate(items):
                for name in ("before", "after") if i % 2 == 0 else ("after", "before"):
                    answers[name][item] = sides[name].ask(item)
                print(
                    f"{item:>12} {answers['before'][item]['ms']:8.0f} ms -> {answers['after'][item]['ms']:6.0f} ms"
                    f"  load {os.getloadavg()[0]:.2f}",
                    flush=True,
                )
        finally:
            for side in sides.values():
                side.close()
    figures = {"before_commit": args.before}
    groups = {"all": items, **{key(eta): [i for i in items if i.endswith(f"@{eta:g}")] for eta in etas}}
    print("\n| coating | before median / max ms | after median / max ms | after / before (medians) |")
    print("|---|---|---|---|")
    for name, group in groups.items():
        figures[name] = summary([answers["before"][i]["ms"] for i in group], [answers["after"][i]["ms"] for i in group])
        f = figures[name]
        print(
            f"| {name} | {f['before_median_ms']:.0f} / {f['before_max_ms']:.0f} | "
            f"{f['after_median_ms']:.0f} / {f['after_max_ms']:.0f} | {f['ratio']:.2f} |"
        )
    tools = list(answers["after"][items[0]]["delta_E"])
    figures["delta_E"] = {
        tool: {
            "mean": float(np.mean([answers["after"][i]["delta_E"][tool]["delta_E_mean"] for i in items])),
            "max": float(np.max([answers["after"][i]["delta_E"][tool]["delta_E_max"] for i in items])),
        }
        for tool in tools
    }
    figures["delta_E_before"] = {
        tool: {
            "mean": float(np.mean([answers["before"][i]["delta_E"][tool]["delta_E_mean"] for i in items])),
            "max": float(np.max([answers["before"][i]["delta_E"][tool]["delta_E_max"] for i in items])),
        }
        for tool in tools
    }
    for stat in ("delta_E_mean", "delta_E_max"):  # the largest rise of one tool's figure on one item, and where
        rise, where = max(
            (answers["after"][i]["delta_E"][tool][stat] - answers["before"][i]["delta_E"][tool][stat], f"{tool} {i}")
            for i in items
            for tool in tools
        )
        figures[f"delta_E_rise_{stat[8:]}"] = {"value": float(rise), "at": where}
    figures["delta_E_change_max"] = float(
        max(
            abs(answers["after"][i]["delta_E"][tool][stat] - answers["before"][i]["delta_E"][tool][stat])
            for i in items
            for tool in tools
            for stat in ("delta_E_mean", "delta_E_max")
        )
    )
    print("\n| tool | Delta E 2000 mean (of the means) | max (of the maxima) |")
    print("|---|---|---|")
    for tool, d in figures["delta_E"].items():
        print(f"| {tool} | {d['mean']:.3f} | {d['max']:.2f} |")
    print(f"\nlargest change of a Delta E between the two checkouts: {figures['delta_E_change_max']:.2e}")
    print("recorded:", write_result(args.output, figures, load_start, materials=materials, eta_i=etas, runs=answers))
    return 0


if __name__ == "__main__":
    sys.exit(main())
