"""
The editor's colour controls: does the fit follow the picked colours?
=====================================================================

For 10 picked (base colour, edge tint) pairs, sRGB hex as an artist types
them, the editor's colour edit is made as the page makes it: the hex
decoded to linear Rec.709 (the sRGB transfer function), the metal's curves
from ``service.jobs.edge_tint.colour_curves`` (the route
``POST /api/v1/colour-curves``) at the rows ``static/editor/colour.js``
``colourRows`` gives (every 0.5 of the domain [1, 2.5], and the slider's
eta_i 1.5; the colours seen in air), then the service's curve fit of those
edits on the base open in the editor (gold, the first material), with the
default settings (``fitting.fits.curves.fit_curves``). Recorded per pair:
CIE Delta E 2000 between the picked base colour and the float16 fit's
colour at normal incidence in air (eta_i 1, cos theta 1), between the
metal's reflectance at 82 degrees in air (the edge tint times Schlick's)
and the fit's there, and the fit's wall and CPU time (this process's).

    .venv/bin/python benchmarks/colour_controls.py   # writes benchmarks/results/colour_controls.json
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.colour.delta_e import delta_E_map  # noqa: E402
from fitting.exports.colour_space import lin_rec709_to_ACEScg  # noqa: E402
from fitting.fits.curves import fit_curves  # noqa: E402
from fitting.fits.curves_base import curve_base_from_nk  # noqa: E402
from fitting.models.kinds import model_ACEScg  # noqa: E402
from fitting.optics.edge_tint import F82_COS_THETA  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from service.jobs.edge_tint import colour_curves  # noqa: E402

__all__ = ["PAIRS", "ROWS", "srgb_hex_to_linear", "follow", "main"]

PAIRS = (
    ("gold", "#ffe29c", "#fff2d9"),
    ("copper", "#fad0c0", "#ffe6d6"),
    ("silver", "#fcf9f5", "#ffffff"),
    ("aluminium", "#f5f6f6", "#f2f4ff"),
    ("iron", "#c4c5c7", "#e6e6e6"),
    ("titanium", "#c2bab1", "#f0e8e0"),
    ("brass", "#f5dc93", "#fff8e0"),
    ("rose gold", "#f2c2b0", "#ffd9cc"),
    ("blue anodised", "#7fa8e0", "#d6e4ff"),
    ("green tint", "#a8d8a0", "#e0ffe0"),
)
"""(name, base colour, edge tint): sRGB hex, as picked."""
ROWS = (1.0, 1.5, 2.0, 2.5)
"""colourRows([1, 2.5], 1.5, 1): the coating indices the editor's colour edit sets."""
BASE = "Au"
SAMPLES = 46


def srgb_hex_to_linear(hex_colour: str) -> np.ndarray:
    """``#rrggbb`` to linear Rec.709 (the sRGB transfer function, as colour-science's eotf_sRGB)."""
    v = np.array([int(hex_colour[i : i + 2], 16) for i in (1, 3, 5)], dtype=np.float64) / 255.0
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def follow(base_hex: str, edge_hex: str, base=None) -> dict:
    """One pair: the editor's colour edit on gold, refitted; the Delta E at normal incidence and at 82 degrees."""
    F0, tint = srgb_hex_to_linear(base_hex), srgb_hex_to_linear(edge_hex)
    answer = colour_curves(F0, tint, "lin_rec709", 1.0, ROWS, SAMPLES)
    theta = np.asarray(answer["theta_deg"])
    curves = [{"eta_i": c["eta_i"], "angle_deg": theta, "rgb": np.asarray(c["rgb"])} for c in answer["curves"]]
    base = base if base is not None else curve_base_from_nk(library_material(BASE))
    start, cpu = time.perf_counter(), time.process_time()
    result = fit_curves(curves, base=base)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    packed = result.packed
    mu = np.array([1.0, F82_COS_THETA])
    fitted = model_ACEScg(packed.model, mu, 1.0, packed.coefficients, packed.eta_i_range)
    schlick = F0 + (1.0 - F0) * (1.0 - F82_COS_THETA) ** 5
    picked = lin_rec709_to_ACEScg(np.stack([F0, tint * schlick]))
    normal, grazing = delta_E_map(picked, fitted)
    return {
        "delta_E_normal": float(normal),
        "delta_E_82": float(grazing),
        "fit_s": seconds,
        "fit_cpu_s": cpu,
        "reachable": bool(all(answer["reachable"])),
    }


def main(argv=None) -> dict:
    argparse.ArgumentParser(description=__doc__.split("\n")[1]).parse_args(argv)
    load = load_average()
    base = curve_base_from_nk(library_material(BASE))
    rows = {name: follow(b, e, base) for name, b, e in PAIRS}
    normal = np.array([r["delta_E_normal"] for r in rows.values()])
    grazing = np.array([r["delta_E_82"] for r in rows.values()])
    times = np.array([r["fit_s"] for r in rows.values()])
    cpu = np.array([r["fit_cpu_s"] for r in rows.values()])
    worst = max(rows, key=lambda name: rows[name]["delta_E_normal"])
    figures = {
        "pairs": len(rows),
        "normal": {
            "mean": float(normal.mean()),
            "max": float(normal.max()),
            "worst": worst,
            "within_1": int(np.sum(normal <= 1.0)),
        },
        "at_82": {"mean": float(grazing.mean()), "max": float(grazing.max())},
        "fit_ms": {"median": float(1e3 * np.median(times)), "max": float(1e3 * times.max())},
        "fit_cpu_ms": {"median": float(1e3 * np.median(cpu)), "max": float(1e3 * cpu.max())},
    }
    for name, r in rows.items():
        print(
            f"{name:14s} dE normal {r['delta_E_normal']:.3f}  dE 82 deg {r['delta_E_82']:.3f}  "
            f"fit {1e3 * r['fit_s']:.0f} ms  reachable {r['reachable']}"
        )
    print(
        f"normal incidence: mean {figures['normal']['mean']:.3f}, max {figures['normal']['max']:.3f} ({worst}); "
        f"load {load}"
    )
    write_result("colour_controls", figures, load, per_pair={n: {"base": b, "edge": e, **rows[n]} for n, b, e in PAIRS})
    return figures


if __name__ == "__main__":
    main()
