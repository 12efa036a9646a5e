"""
three.js: the package's WebGL material against its node material (WebGPURenderer)
===================================================================================

For each library material and model kind, a fit made in-process and its
glTF extension object at each coat index, drawn on one page
(tests/static/three_node_pages.py) by ``WebGLRenderer`` with the package's
material and by ``WebGPURenderer`` with its node material
(``coated-conductor-three/webgpu``), both read back as float radiance in
Chromium (SwiftShader; headless Chromium has no WebGPU adapter, so the
WebGPURenderer runs its WebGL2 backend, ``forceWebGL``), 128 x 128, the
package test's shader ball and camera:

-   **smooth**: metal and coat mirrors under the white sky at every coat
    index of :data:`SMOOTH_ETAS` (1.0 to 2.0), the scenes of the package's
    tests;
-   **rough, lit**: :data:`ROUGH_SETTINGS` under the white sky and a white
    directional light (the direct-light path, which the sky alone leaves
    out), at eta_i 1.5.

Mean Delta E 2000 between the two images over the ball's pixels with
NdotV >= 0.1, its 99th percentile and max; each scene's time (both
renderers, the first with the shaders' compilation). Prints a Markdown table
and records it::

    .venv/bin/python benchmarks/three_node_parity.py                     # about 4 min here, loaded
    .venv/bin/python benchmarks/three_node_parity.py --materials Au --result -
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

from benchmarks.record import write_result  # noqa: E402
from editor_pages import CHROMIUM_ARGS  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402
from three_node_pages import draw_both, parity, parity_page, write_folder  # noqa: E402
from three_pages import serve  # noqa: E402

from fitting.exports import export_material  # noqa: E402
from fitting.fits.kinds import fit_model  # noqa: E402
from fitting.models.kinds import MODEL_KINDS  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402

SMOOTH_ETAS = (1.0, 1.33, 1.5, 2.0)
# (metal roughness, coat roughness) at eta_i 1.5, white sky and a directional light.
ROUGH_SETTINGS = ((0.3, 0.1), (0.6, 0.3))
ROUGH_ETA = 1.5
ETA_RANGE = (1.0, 2.5)
BOUND = 0.05


def extension(nk, packed, eta_i: float) -> dict:
    """The glTF export's EXT_materials_coated_conductor object at coat index ``eta_i``."""
    document = json.loads(export_material(nk, "gltf", eta_i, model=packed))
    return document["materials"][0]["extensions"]["EXT_materials_coated_conductor"]


def _spread(found: list[dict]) -> dict:
    """Mean of the scenes' means, the worst scene's mean, 99th percentile and pixel."""
    return {
        "mean": sum(f["mean"] for f in found) / len(found),
        "worst_mean": max(f["mean"] for f in found),
        "worst_p99": max(f["p99"] for f in found),
        "worst_max": max(f["max"] for f in found),
        "scenes": len(found),
    }


def figures(rows: list[dict]) -> dict:
    """``smooth`` and ``rough_lit``: all kinds and each kind; the scenes within BOUND; the time per scene."""
    out: dict = {"scenes": len(rows), "materials": len({r["material"] for r in rows}), "bound": BOUND}
    for label in ("smooth", "rough_lit"):
        of = [r for r in rows if r["scene"] == label]
        if of:
            out[label] = {"all": _spread(of)} | {
                kind: _spread([r for r in of if r["kind"] == kind]) for kind in sorted({r["kind"] for r in of})
            }
    out["within_bound"] = sum(r["mean"] <= BOUND for r in rows)
    times = sorted(r["seconds"] for r in rows[1:]) or [rows[0]["seconds"]]
    out["scene_seconds"] = {"first": rows[0]["seconds"], "median_after": times[len(times) // 2]}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--materials", default="Ag,Al,Au,Cu,Cr,CuZn", help="comma-separated library materials")
    parser.add_argument(
        "--result", default="three_node_parity", help="name of the record, benchmarks/results/NAME.json ('-': none)"
    )
    args = parser.parse_args()
    load = os.getloadavg()[0]
    scenes = []
    for material in args.materials.split(","):
        nk = library_material(material)
        for kind in MODEL_KINDS:
            packed = fit_model(nk, ETA_RANGE, kind).packed
            scenes += [(material, kind, "smooth", eta, extension(nk, packed, eta), 0.0, 0.0) for eta in SMOOTH_ETAS]
            lit = extension(nk, packed, ROUGH_ETA)
            scenes += [(material, kind, "rough_lit", ROUGH_ETA, lit, r, c) for r, c in ROUGH_SETTINGS]
    rows = []
    with tempfile.TemporaryDirectory() as folder, sync_playwright() as playwright:
        write_folder(Path(folder))
        browser = playwright.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS)
        try:
            with serve(Path(folder)) as site, parity_page(browser, site) as (page, errors, backend):
                for material, kind, scene, eta, model, roughness, coat_roughness in scenes:
                    started = time.perf_counter()
                    webgl, node = draw_both(page, model, roughness, coat_roughness, scene == "rough_lit", coat_ior=eta)
                    seconds = time.perf_counter() - started
                    found = parity(webgl, node)
                    rows.append(
                        {
                            "material": material,
                            "kind": kind,
                            "scene": scene,
                            "eta_i": eta,
                            "roughness": roughness,
                            "coat_roughness": coat_roughness,
                            "seconds": seconds,
                            **found,
                        }
                    )
                    print(
                        f"{material} {kind} {scene} {eta} {roughness} {coat_roughness}: mean {found['mean']:.2e}, "
                        f"max {found['max']:.2e} ({seconds:.1f} s)",
                        file=sys.stderr,
                    )
                if errors:
                    raise SystemExit(f"the page reported errors: {errors}")
        finally:
            browser.close()
    print("| material | kind | scene | eta_i | roughness | coat roughness | mean | p99 | max |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        print(
            f"| {r['material']} | {r['kind']} | {r['scene']} | {r['eta_i']:g} | {r['roughness']:g} | "
            f"{r['coat_roughness']:g} | {r['mean']:.2e} | {r['p99']:.2e} | {r['max']:.2e} |"
        )
    result = figures(rows)
    result["backend"] = backend
    print(json.dumps(result, indent=2))
    if args.result != "-":
        three = json.loads((ROOT / "scripts" / "three" / "package-lock.json").read_text())
        version = three["packages"]["node_modules/three"]["version"]
        write_result(args.result, result, load, three=version, rows=rows)


if __name__ == "__main__":
    main()
