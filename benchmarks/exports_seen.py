"""
Exports: what the user sees in each tool
========================================

For each tool, coating index eta_i and library conductor, the Delta E 2000
(mean and max over the view angles 0 to 83 degrees in air, steps of 1,
roughness 0, a uniform white sky) between the physical coat on the metal
seen from air (:func:`fitting.colour.seen.seen_ACEScg`: both polarisations,
the metal at the refracted angle, the bounces between the interfaces, 1 nm)
and the tool's layered result (:mod:`fitting.exports.tool_layering`, numpy
mirrors of each tool's layering, checked against the tools' own renders by
``tests/fitting/exports/test_tool_layering_renders.py``):

-   ``seen``: the export as written now (values fitted to the seen target);
-   ``floor``: the tool's layering over a perfect base (the best base
    response in [0, 1] per angle and channel);
-   ``naive``: the export before issue 22 (base Fresnel fitted to the
    metal under the coat at the same angle inside the coat; at eta_i 1 the
    ``mtlx`` / ``openpbr`` coat of index 1 and glTF's clear coat factor 1
    kept; OpenPBR with ``coat_darkening`` 0).

Tools: ``mtlx`` (MaterialX layer + dielectric_bsdf over conductor_bsdf),
``openpbr`` (open_pbr_surface, coat_darkening as exported), ``blender``
(Cycles Principled coat over its F82 metal), ``blender-conductor`` (the
Blender export's Metallic BSDF under a Fresnel-mixed Glossy coat),
``gltf`` (three.js MeshPhysicalMaterial with clearcoat).

    .venv/bin/python benchmarks/exports_seen.py [--eta-i 1.0,1.33,1.5,2.0] [--materials Au,Cu]

Prints a Markdown table and records benchmarks/results/exports_seen.json.
"""

from __future__ import annotations

import argparse
import json
from datetime import datetime, timezone
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fitting.colour.seen import SEEN_ANGLES_DEG, seen_ACEScg  # noqa: E402
from fitting.exports.colour_space import ACEScg_to_lin_rec709  # noqa: E402
from fitting.exports.seen_fit import fit_tool_values, seen_delta_E, tool_floor  # noqa: E402
from fitting.exports.tool_layering import TOOLS  # noqa: E402
from fitting.exports.values import export_values, has_coat  # noqa: E402
from fitting.optics.library import LIBRARY_NAMES, library_material  # noqa: E402

RESULT = ROOT / "benchmarks" / "results" / "exports_seen.json"
CONDUCTOR_TOOLS = ("mtlx", "blender-conductor")


def naive_values(values, tool: str) -> dict:
    """Today's (before issue 22) export values of ``tool``, and its coat."""
    if tool in CONDUCTOR_TOOLS:
        v = {"ior": values.n_rel, "extinction": values.k_rel}
    elif tool == "openpbr":
        v = {"base_color": values.F0, "specular_color": values.F82_tint, "coat_darkening": 0.0}
    elif tool == "blender":
        v = {"base_color": values.F0, "specular_tint": values.F82_tint}
    else:
        v = {"base_color": values.F0_schlick, "clearcoat": 1.0}
    # Every export had a coat, of index eta_i (glTF: its own 1.5).
    return {**v, "coat": True}


def material_rows(name: str, eta: float) -> dict:
    nk = library_material(name)
    mu = np.cos(np.radians(SEEN_ANGLES_DEG))
    target = seen_ACEScg(nk, mu, eta)
    values = export_values(nk, eta, tools=())
    coat = has_coat(eta)
    holdable = bool(np.all((ACEScg_to_lin_rec709(target) >= 0.0) & (ACEScg_to_lin_rec709(target) <= 1.0)))
    out = {"holdable_in_rec709": holdable}
    for tool in TOOLS:
        fitted = fit_tool_values(tool, mu, eta, target, coat)
        seen = seen_delta_E(tool, fitted, mu, eta, target)
        floor = tool_floor(tool, mu, eta, target, coat)
        naive = seen_delta_E(tool, naive_values(values, tool), mu, eta, target)
        out[tool] = {
            "seen": [float(seen.mean()), float(seen.max())],
            "floor": [float(floor.mean()), float(floor.max())],
            "naive": [float(naive.mean()), float(naive.max())],
        }
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/exports_seen.py")
    parser.add_argument("--eta-i", default="1.0,1.33,1.5,2.0")
    parser.add_argument("--materials", default=",".join(LIBRARY_NAMES))
    parser.add_argument("--no-record", action="store_true")
    args = parser.parse_args(argv)
    etas = [float(e) for e in args.eta_i.split(",")]
    names = args.materials.split(",")
    started = time.time()
    results = {f"{eta:g}": {name: material_rows(name, eta) for name in names} for eta in etas}
    print("| tool | eta_i | seen mean / max | floor mean / max | naive mean / max | worst seen |")
    print("|---|---:|---|---|---|---|")
    summary = {}
    for tool in TOOLS:
        for eta in etas:
            rows = results[f"{eta:g}"]
            cell = {}
            for key in ("seen", "floor", "naive"):
                means = [rows[n][tool][key][0] for n in names]
                maxes = [rows[n][tool][key][1] for n in names]
                cell[key] = [float(np.mean(means)), float(np.max(maxes))]
            worst = max(names, key=lambda n: rows[n][tool]["seen"][0])
            cell["worst"] = [worst, rows[worst][tool]["seen"][0]]
            summary.setdefault(tool, {})[f"{eta:g}"] = cell
            print(f"| {tool} | {eta:g} | {cell['seen'][0]:.3f} / {cell['seen'][1]:.2f} | "
                  f"{cell['floor'][0]:.3f} / {cell['floor'][1]:.2f} | "
                  f"{cell['naive'][0]:.3f} / {cell['naive'][1]:.2f} | {worst} {cell['worst'][1]:.2f} |")
    for eta in etas:
        rows = results[f"{eta:g}"]
        for tool in CONDUCTOR_TOOLS:
            held = [n for n in names if rows[n]["holdable_in_rec709"]]
            over = [n for n in held if rows[n][tool]["seen"][0] >= 1.0]
            print(f"eta_i {eta:g} {tool}: {len(held)} of {len(names)} metals holdable in Rec.709; "
                  f"seen mean >= 1.0 on {over or 'none'}")
    elapsed = time.time() - started
    load = os.getloadavg()
    print(f"{elapsed:.0f} s, load average {load[0]:.1f}")
    if not args.no_record:
        RESULT.parent.mkdir(parents=True, exist_ok=True)
        RESULT.write_text(json.dumps({
            "command": "benchmarks/exports_seen.py " + " ".join(argv or sys.argv[1:]),
            "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
            "angles_deg": [float(SEEN_ANGLES_DEG[0]), float(SEEN_ANGLES_DEG[-1])],
            "summary": summary, "per_material": results,
            "seconds": round(elapsed, 1), "load_average": round(load[0], 2),
        }, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
