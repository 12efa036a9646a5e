"""
How much a gap in the data moves the reference: the default largest gap.

For each library conductor and each gap width, the samples inside a window
of that width are removed at every position (centre every 10 nm over
380-810 nm) and the 1 nm spectral reference of the thinned data is scored
against the full data's on 12 angles x 3 eta_i (Delta E 2000, worst over
positions). Also the widest spacing of each data set inside 360-830 nm.
Writes benchmarks/results/data_gaps.json.

Usage: python benchmarks/data_gaps.py
"""

from __future__ import annotations

import json
from datetime import datetime, timezone
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fitting import LIBRARY_NAMES, library_material  # noqa: E402
from fitting.colour.delta_e import delta_E_map  # noqa: E402
from fitting.colour.reference import reference_ACEScg_grid  # noqa: E402
from fitting.optics.nk import SpectralNK  # noqa: E402
from fitting.optics.quality import visible_gaps  # noqa: E402

WIDTHS = (60, 80, 100, 120, 150)


def main() -> int:
    mu, eta = np.linspace(0, 1, 12), np.array([1.0, 1.75, 2.5])
    rows = {}
    print(f"{'material':8s} {'widest':>7s} " + " ".join(f"{w:>6d}" for w in WIDTHS))
    for name in LIBRARY_NAMES:
        nk = library_material(name)
        w = nk.wavelength_nm
        ref = reference_ACEScg_grid(nk, mu, eta, 1.0)
        gaps = visible_gaps(w)
        widest = gaps[0][1] - gaps[0][0] if gaps else 0.0
        worst = {}
        for width in WIDTHS:
            m = 0.0
            for centre in np.arange(380, 811, 10):
                keep = (w < centre - width / 2) | (w > centre + width / 2)
                if keep.sum() < 2:
                    continue
                thin = SpectralNK(w[keep], nk.n[keep], nk.k[keep], name="thinned")
                try:
                    m = max(m, float(delta_E_map(ref, reference_ACEScg_grid(thin, mu, eta, 1.0, 0.0)).max()))
                except ValueError:
                    continue
            worst[width] = m
        rows[name] = {"widest_gap_nm": widest, "worst_delta_E_by_gap_nm": worst}
        print(f"{name:8s} {widest:7.0f} " + " ".join(f"{worst[x]:6.2f}" for x in WIDTHS), flush=True)
    summary = {
        "widest_gap_in_library_nm": max(r["widest_gap_nm"] for r in rows.values()),
        "conductors_moved_over_2_by_gap_nm": {
            str(x): sum(r["worst_delta_E_by_gap_nm"][x] > 2 for r in rows.values()) for x in WIDTHS
        },
        "worst_delta_E_by_gap_nm": {
            str(x): max(r["worst_delta_E_by_gap_nm"][x] for r in rows.values()) for x in WIDTHS
        },
    }
    print(json.dumps(summary, indent=1))
    out = Path(__file__).resolve().parent / "results" / "data_gaps.json"
    out.write_text(
        json.dumps(
            {
                "command": "python benchmarks/data_gaps.py",
                "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
                "load_average": os.getloadavg(),
                "summary": summary,
                "materials": rows,
            },
            indent=1,
        )
        + "\n"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
