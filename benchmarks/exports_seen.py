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

-   ``seen``: the export as written now (values fitted to the seen target;
    the conductor exports' index affine in 1 - cos theta where it fits better);
-   ``constant`` (conductor tools only): their constant index, slopes 0
    (the conductor exports before the view-dependent index);
-   ``floor``: the tool's layering over a perfect base (the best base
    response in [0, 1] per angle and channel);
-   ``naive``: the export before the seen fit (base Fresnel fitted to the
    metal under the coat at the same angle inside the coat; at eta_i 1 the
    ``mtlx`` / ``openpbr`` coat of index 1 and glTF's clear coat factor 1
    kept; OpenPBR with ``coat_darkening`` 0).

Tools: ``mtlx`` (MaterialX layer + dielectric_bsdf over conductor_bsdf),
``openpbr`` (open_pbr_surface, coat_darkening as exported), ``blender``
(Cycles Principled coat over its F82 metal), ``blender-conductor`` (the
Blender export's Metallic BSDF under a Fresnel-mixed Glossy coat),
``gltf`` (three.js MeshPhysicalMaterial with clearcoat).

    .venv/bin/python benchmarks/exports_seen.py [--eta-i 1.0,1.33,1.5,2.0] [--materials Au,Cu]

Prints a Markdown table and records benchmarks/results/exports_seen.json
(its ``figures``: the same keyed ``eta_i_1_5``, for the docs' markers).

``--conductor-search`` measures instead how low the conductor exports can
go with constant values (the criterion, before the view-dependent index): for each conductor tool and metal
(``--materials``, default W and CuZn) at ``--eta-i`` (default 1.5), a
multi-start search over the six values, n in [0.001, 20] and k in [0, 50]
per channel (the fit's full bounds), with the mean Delta E itself as the
objective (residuals sqrt(Delta E + 1e-6), so that their sum of squares is
the sum of Delta E over the angles), scipy ``least_squares`` (``trf``, at
most 600 evaluations) from :func:`search_starts`: the shipped fit, a grid of
equal-channel starts (low-n high-k to high-n k-free) and seeded random
per-channel starts. It records the best mean found per metal and tool, and
the best per kind of start, under ``conductor_search`` (keyed ``eta_i_1_5``) in the same record
(the rest of the record is kept).

``--view-dependent`` measures the form the conductor exports now carry
(:func:`fitting.exports.seen_fit.fit_view_dependent_index`, there with the
fit's RMS objective, at most 60 evaluations, from the constant fit), with the
mean objective and a larger budget: the conductor's n and k per channel driven by the view angle,
affine in 1 - cos theta (Blender: Layer Weight's Facing into the Metallic
BSDF's IOR and Extinction; MaterialX: a node graph of ``normal`` and
``viewdirection`` into ``conductor_bsdf``'s ior and extinction), twelve
values, fitted in the mirrors from the shipped fit (:func:`view_dependent_index`),
recorded under ``view_dependent_index``; ``shipped`` there is the constant
fit (both search modes start from it). Exact in the mirrors at roughness 0 only.
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
from scipy.optimize import least_squares

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fitting.colour.seen import SEEN_ANGLES_DEG, seen_ACEScg  # noqa: E402
from fitting.exports.colour_space import ACEScg_to_lin_rec709  # noqa: E402
from fitting.exports.seen_fit import K_BOUNDS, N_BOUNDS, fit_tool_values, seen_delta_E, tool_floor  # noqa: E402
from fitting.exports.tool_layering import TOOLS  # noqa: E402
from fitting.exports.values import export_values, has_coat  # noqa: E402
from fitting.optics.library import LIBRARY_NAMES, library_material  # noqa: E402

RESULT = ROOT / "benchmarks" / "results" / "exports_seen.json"
CONDUCTOR_TOOLS = ("mtlx", "blender-conductor")


def naive_values(values, tool: str) -> dict:
    """The earlier (naive) export values of ``tool``, and its coat."""
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
        if tool in CONDUCTOR_TOOLS:
            # The constant index (slopes 0): the conductor exports before the view-dependent one.
            constant = seen_delta_E(
                tool, fit_tool_values(tool, mu, eta, target, coat, view_dependent=False), mu, eta, target
            )
            out[tool]["constant"] = [float(constant.mean()), float(constant.max())]
    return out


SEARCH_GRID_N = (0.01, 0.1, 0.5, 1.0, 2.0, 4.0, 8.0, 19.0)
SEARCH_GRID_K = (0.0, 0.5, 1.5, 4.0, 12.0, 40.0)
SEARCH_RANDOM = 16
SEARCH_MAX_NFEV = 600


def search_starts(shipped: np.ndarray) -> list[tuple[str, np.ndarray]]:
    """
    The starts of the conductor search, each ``(kind, x)`` with
    ``x = (n_r, n_g, n_b, k_r, k_g, k_b)``: the shipped fit; every pair of
    :data:`SEARCH_GRID_N` x :data:`SEARCH_GRID_K` on all three channels;
    :data:`SEARCH_RANDOM` per-channel draws (seed 0), n log-uniform over its
    bounds, k 0 or log-uniform in [0.01, 50], each half the time.
    """
    starts = [("shipped", np.asarray(shipped, dtype=np.float64))]
    starts += [("grid", np.r_[[n] * 3, [k] * 3]) for n in SEARCH_GRID_N for k in SEARCH_GRID_K]
    rng = np.random.default_rng(0)
    for _ in range(SEARCH_RANDOM):
        n = np.exp(rng.uniform(np.log(N_BOUNDS[0]), np.log(N_BOUNDS[1]), 3))
        k = np.where(rng.random(3) < 0.5, 0.0, np.exp(rng.uniform(np.log(0.01), np.log(K_BOUNDS[1]), 3)))
        starts.append(("random", np.r_[n, k]))
    return starts


def conductor_search(tool: str, name: str, eta: float) -> dict:
    """The best seen mean Delta E the conductor values of ``tool`` reach for ``name``, from every start."""
    mu = np.cos(np.radians(SEEN_ANGLES_DEG))
    target = seen_ACEScg(library_material(name), mu, eta)
    lo = np.r_[[N_BOUNDS[0]] * 3, [K_BOUNDS[0]] * 3]
    hi = np.r_[[N_BOUNDS[1]] * 3, [K_BOUNDS[1]] * 3]

    def delta_E(x):
        return seen_delta_E(tool, {"ior": x[:3], "extinction": x[3:], "coat": True}, mu, eta, target)

    shipped = fit_tool_values(tool, mu, eta, target, True, view_dependent=False)
    x_shipped = np.r_[shipped["ior"], shipped["extinction"]]
    started = time.process_time()
    best, by_kind = None, {}
    for kind, x0 in search_starts(x_shipped):
        x0 = np.clip(x0, lo + 1e-9, hi - 1e-9)
        fit = least_squares(
            lambda x: np.sqrt(delta_E(x) + 1e-6),
            x0,
            bounds=(lo, hi),
            method="trf",
            x_scale="jac",
            diff_step=1e-6,
            max_nfev=SEARCH_MAX_NFEV,
        )
        dE = delta_E(fit.x)
        mean = float(dE.mean())
        by_kind[kind] = min(by_kind.get(kind, np.inf), mean)
        if best is None or mean < best["mean"]:
            best = {
                "mean": mean,
                "max": float(dE.max()),
                "from": kind,
                "ior": fit.x[:3].tolist(),
                "extinction": fit.x[3:].tolist(),
            }
    shipped_dE = delta_E(x_shipped)
    return {
        "shipped": [float(shipped_dE.mean()), float(shipped_dE.max())],
        "best": best,
        "best_by_start": by_kind,
        "starts": len(search_starts(x_shipped)),
        "cpu_s": round(time.process_time() - started, 1),
    }


def view_dependent_index(tool: str, name: str, eta: float) -> dict:
    """
    The seen Delta E of the conductor of ``tool`` with n_c + n'_c (1 - mu) and
    k_c + k'_c (1 - mu) per channel (clipped to the fit's bounds), fitted from
    the shipped values (slopes 0) with the mean Delta E as objective.
    """
    mu = np.cos(np.radians(SEEN_ANGLES_DEG))
    target = seen_ACEScg(library_material(name), mu, eta)
    facing = (1.0 - mu)[:, None]

    def delta_E(x):
        n = np.clip(x[0:3] + x[3:6] * facing, *N_BOUNDS)
        k = np.clip(x[6:9] + x[9:12] * facing, *K_BOUNDS)
        return seen_delta_E(tool, {"ior": n, "extinction": k, "coat": True}, mu, eta, target)

    shipped = fit_tool_values(tool, mu, eta, target, True, view_dependent=False)
    x0 = np.r_[shipped["ior"], [0.0] * 3, shipped["extinction"], [0.0] * 3]
    fit = least_squares(
        lambda x: np.sqrt(delta_E(x) + 1e-6), x0, method="trf", x_scale="jac", diff_step=1e-6, max_nfev=SEARCH_MAX_NFEV
    )
    dE, dE0 = delta_E(fit.x), delta_E(x0)
    return {
        "shipped": [float(dE0.mean()), float(dE0.max())],
        "view_dependent": [float(dE.mean()), float(dE.max())],
        "ior": fit.x[0:3].tolist(),
        "ior_per_facing": fit.x[3:6].tolist(),
        "extinction": fit.x[6:9].tolist(),
        "extinction_per_facing": fit.x[9:12].tolist(),
    }


def run_conductor_search(names: list[str], etas: list[float], record: bool, argv, view_dependent: bool) -> int:
    """
    ``--conductor-search`` (:func:`conductor_search`) or ``--view-dependent``
    (:func:`view_dependent_index`): print and record it per eta_i, tool and metal.
    """
    started = time.time()
    found = {}
    for eta in etas:
        for tool in CONDUCTOR_TOOLS:
            for name in names:
                row = (view_dependent_index if view_dependent else conductor_search)(tool, name, eta)
                found.setdefault(eta_key(eta), {}).setdefault(tool, {})[name] = row
                if view_dependent:
                    print(
                        f"eta_i {eta:g} {tool} {name}: shipped {row['shipped'][0]:.3f}, view-dependent "
                        f"{row['view_dependent'][0]:.3f} / max {row['view_dependent'][1]:.2f}",
                        flush=True,
                    )
                    continue
                b = row["best"]
                print(
                    f"eta_i {eta:g} {tool} {name}: shipped {row['shipped'][0]:.3f}, best of {row['starts']} "
                    f"starts {b['mean']:.3f} / max {b['max']:.2f} (from {b['from']}; n {np.round(b['ior'], 3)}, "
                    f"k {np.round(b['extinction'], 3)}); {row['cpu_s']:.0f} s CPU",
                    flush=True,
                )
    elapsed = time.time() - started
    load = os.getloadavg()
    print(f"{elapsed:.0f} s, load average {load[0]:.1f}")
    if record:
        data = json.loads(RESULT.read_text()) if RESULT.exists() else {}
        run = {
            "command": "benchmarks/exports_seen.py " + " ".join(argv),
            "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
            "starts": {
                "grid_n": SEARCH_GRID_N,
                "grid_k": SEARCH_GRID_K,
                "random": SEARCH_RANDOM,
                "max_nfev": SEARCH_MAX_NFEV,
            },
            "found": found,
            "seconds": round(elapsed, 1),
            "load_average": round(load[0], 2),
        }
        if view_dependent:
            run["starts"] = {"shipped": 1, "max_nfev": SEARCH_MAX_NFEV}
        data["view_dependent_index" if view_dependent else "conductor_search"] = run
        RESULT.write_text(json.dumps(data, indent=1) + "\n")
    return 0


def eta_key(eta) -> str:
    """``eta_i_1_5`` for 1.5: a key the docs' dotted figure paths can name (benchmarks.docs_figures)."""
    return f"eta_i_{float(eta):g}".replace(".", "_")


def figures(record: dict) -> dict:
    """
    The record's ``summary`` and ``per_material`` keyed by :func:`eta_key`
    (``summary_by_eta.<tool>.eta_i_1_5.seen.0``, ``material_by_eta.eta_i_1_5.W.mtlx.seen.0``),
    what docs/exports.md's seen tables quote.
    """
    return {
        "summary_by_eta": {
            tool: {eta_key(eta): cell for eta, cell in cells.items()} for tool, cells in record["summary"].items()
        },
        "material_by_eta": {eta_key(eta): rows for eta, rows in record["per_material"].items()},
        # The conductor tools' constant index (slopes 0): mean over the metals, max.
        "constant_by_eta": {
            tool: {
                eta_key(eta): [
                    float(np.mean([r[tool]["constant"][0] for r in rows.values()])),
                    float(np.max([r[tool]["constant"][1] for r in rows.values()])),
                ]
                for eta, rows in record["per_material"].items()
            }
            for tool in CONDUCTOR_TOOLS
        },
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/exports_seen.py")
    parser.add_argument("--eta-i", default=None, help="default 1.0,1.33,1.5,2.0 (--conductor-search: 1.5)")
    parser.add_argument("--materials", default=None, help="default all (--conductor-search: W,CuZn)")
    parser.add_argument("--no-record", action="store_true")
    parser.add_argument(
        "--conductor-search", action="store_true", help="the multi-start search of the conductor exports' values"
    )
    parser.add_argument(
        "--view-dependent", action="store_true", help="the conductor with n, k affine in 1 - cos theta, in the mirrors"
    )
    args = parser.parse_args(argv)
    argv = sys.argv[1:] if argv is None else argv
    search = args.conductor_search or args.view_dependent
    etas = [float(e) for e in (args.eta_i or ("1.5" if search else "1.0,1.33,1.5,2.0")).split(",")]
    names = (args.materials or ("W,CuZn" if search else ",".join(LIBRARY_NAMES))).split(",")
    if search:
        return run_conductor_search(names, etas, not args.no_record, argv, args.view_dependent)
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
            print(
                f"| {tool} | {eta:g} | {cell['seen'][0]:.3f} / {cell['seen'][1]:.2f} | "
                f"{cell['floor'][0]:.3f} / {cell['floor'][1]:.2f} | "
                f"{cell['naive'][0]:.3f} / {cell['naive'][1]:.2f} | {worst} {cell['worst'][1]:.2f} |"
            )
    for eta in etas:
        rows = results[f"{eta:g}"]
        for tool in CONDUCTOR_TOOLS:
            held = [n for n in names if rows[n]["holdable_in_rec709"]]
            over = [n for n in held if rows[n][tool]["seen"][0] >= 1.0]
            print(
                f"eta_i {eta:g} {tool}: {len(held)} of {len(names)} metals holdable in Rec.709; "
                f"seen mean >= 1.0 on {over or 'none'}"
            )
    elapsed = time.time() - started
    load = os.getloadavg()
    print(f"{elapsed:.0f} s, load average {load[0]:.1f}")
    if not args.no_record:
        RESULT.parent.mkdir(parents=True, exist_ok=True)
        # The conductor searches' records are their own runs': kept across this one.
        kept = {
            k: v
            for k, v in (json.loads(RESULT.read_text()) if RESULT.exists() else {}).items()
            if k in ("conductor_search", "view_dependent_index")
        }
        record = {
            "command": "benchmarks/exports_seen.py " + " ".join(argv),
            "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
            "angles_deg": [float(SEEN_ANGLES_DEG[0]), float(SEEN_ANGLES_DEG[-1])],
            "summary": summary,
            "per_material": results,
            "seconds": round(elapsed, 1),
            "load_average": round(load[0], 2),
            **kept,
        }
        record["figures"] = figures(record)
        RESULT.write_text(json.dumps(record, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
