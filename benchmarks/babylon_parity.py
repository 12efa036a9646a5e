"""
Babylon.js against three.js through EXT_materials_coated_conductor
====================================================================

Two independent renderers draw the extension: for each library material
and model kind, a fit stored on a server just started, its glTF export at
each coat index of ``--etas`` loaded by Babylon.js (/examples/babylon.html,
coated-conductor-babylon's glTF loader extension and PBRMaterial plugin)
and by three.js (/examples/three.html, coated-conductor-three's GLTFLoader
plugin), both smooth under a uniform white sky with the same camera, read
back as float radiance in Chromium (SwiftShader WebGL2), 128 x 128, and
compared per pixel (tests/static/babylon_pages.py): mean Delta E 2000 over
the ball's pixels with NdotV >= 0.1, its 99th percentile, max, centre and
ring near grazing. Prints the table and records it::

    .venv/bin/python benchmarks/babylon_parity.py --materials Au,Cu,Ag,Al,Cr   # 2.5 to 4.5 min here, loaded
    .venv/bin/python benchmarks/babylon_parity.py --materials Au --result -
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "static"))

from babylon_pages import measure_babylon, show_babylon  # noqa: E402
from benchmarks.record import write_result  # noqa: E402
from conftest import server_process  # noqa: E402
from editor_pages import CHROMIUM_ARGS  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402
from three_pages import create_fit, open_example, show_fit  # noqa: E402

from fitting.models.kinds import MODEL_KINDS  # noqa: E402

ETAS = "1.0,1.5,2.0"


def babylon_version() -> str:
    """@babylonjs/core's version as scripts/babylon/package-lock.json pins it."""
    lock = json.loads((ROOT / "scripts" / "babylon" / "package-lock.json").read_text())
    return lock["packages"]["node_modules/@babylonjs/core"]["version"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--materials", default="Au,Cu,Ag,Al,Cr", help="comma-separated library materials")
    parser.add_argument("--etas", default=ETAS, help="comma-separated coat indices")
    parser.add_argument(
        "--result",
        default="babylon_parity",
        help="name of the figures' record, benchmarks/results/NAME.json ('-': none)",
    )
    args = parser.parse_args()
    materials = args.materials.split(",")
    etas = [float(e) for e in args.etas.split(",")]
    rows = []
    started = time.perf_counter()
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data") as server:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS)
            three = browser.new_page(viewport={"width": 900, "height": 700})
            babylon = browser.new_page(viewport={"width": 900, "height": 700})
            for page in (three, babylon):
                page.set_default_timeout(300_000)
            opened = False
            for material in materials:
                for kind in MODEL_KINDS:
                    fit = create_fit(server.url, material, kind)
                    for eta_i in etas:
                        if opened:
                            show_fit(three, fit["id"], eta_i)
                        else:
                            open_example(three, server.url, fit["id"], eta_i, "white_sky")
                            opened = True
                        show_babylon(babylon, server.url, fit["id"], eta_i)
                        f = measure_babylon(three, babylon)
                        rows.append(
                            {
                                "material": material,
                                "kind": kind,
                                "eta_i": eta_i,
                                **f["babylon_vs_three"],
                                "pixels": f["pixels"],
                            }
                        )
                        print(
                            f"{material} {kind} {eta_i}: mean {rows[-1]['mean']:.3f} max {rows[-1]['max']:.3f}",
                            file=sys.stderr,
                        )
            browser.close()
    load = max(load, os.getloadavg()[0])
    print("| material | kind | eta_i | mean | p99 | max | centre | ring |\n|---|---|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(
            f"| {r['material']} | {r['kind']} | {r['eta_i']} | {r['mean']:.3f} | {r['p99']:.3f} | "
            f"{r['max']:.3f} | {r['centre']:.3f} | {r['ring']:.3f} |"
        )
    worst = max(rows, key=lambda r: r["mean"])
    summary = {
        "settings": len(rows),
        "mean_of_means": sum(r["mean"] for r in rows) / len(rows),
        "worst_mean": worst["mean"],
        "worst_case": f"{worst['material']} {worst['kind']} eta_i {worst['eta_i']}",
        "worst_p99": max(r["p99"] for r in rows),
        "worst_ring": max(r["ring"] for r in rows),
        "rows": rows,
    }
    if args.result != "-":
        path = write_result(
            args.result,
            summary,
            load,
            materials=materials,
            etas=etas,
            seconds=round(time.perf_counter() - started),
            babylon=babylon_version(),
        )
        print(f"recorded in {path.relative_to(ROOT)}", file=sys.stderr)
    else:
        print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
