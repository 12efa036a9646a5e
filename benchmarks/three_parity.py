"""
three.js through EXT_materials_coated_conductor against the preview and the physics
===================================================================================

For each library material, model kind, coat index eta_i, preview
environment (white sky, studio, outdoor) and lobe setting (metal roughness,
coat roughness): a fit stored on a server just started, its glTF export
loaded on /examples/three.html with the plugin and without it (one page load
per fit and eta_i: the page relights and the material takes each roughness
in turn), and both balls read back as float radiance in Chromium
(SwiftShader WebGL2), 128 x 128, against

-   the editor's WebGL preview at the same settings, both kinds (the preview
    draws the rgb-conductor kind too);
-   under the white sky, also numpy's twin of an rgb-conductor material
    (split sum of its exact Fresnel, the same coat), the physics (the 1 nm
    spectral reference under the coat in the coated split sum,
    tests/static/three_pages.py), and the fallback ball (no plugin: Schlick
    base colour and KHR_materials_clearcoat) against the same physics.

Mean Delta E 2000 over the ball's pixels with NdotV >= 0.1, its 99th
percentile, its max, the mean at the centre (NdotV >= 0.97) and on the ring near
grazing (NdotV in [0.1, 0.25]). Prints a Markdown table and records it::

    .venv/bin/python benchmarks/three_parity.py            # about 4 min here
    .venv/bin/python benchmarks/three_parity.py --materials Au --environments studio --record -
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
from conftest import server_process  # noqa: E402
from editor_pages import CHROMIUM_ARGS  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402
from three_pages import create_fit, measure_three, open_example  # noqa: E402

from fitting.models.kinds import MODEL_KINDS  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402

# (eta_i, [(metal roughness, coat roughness), ...]): the settings of one page load.
SETTINGS = [(1.5, [(0.0, 0.0), (0.3, 0.1)]), (2.2, [(0.5, 0.2)])]
ENVIRONMENTS = ("white_sky", "studio", "outdoor")
KINDS = tuple(MODEL_KINDS)
RECORD = ROOT / "benchmarks" / "records" / "three_parity.md"


def three_version() -> str:
    """three's version as scripts/three/package-lock.json pins it."""
    lock = json.loads((ROOT / "scripts" / "three" / "package-lock.json").read_text())
    return lock["packages"]["node_modules/three"]["version"]


def _row(material, kind, env, eta_i, r, c, f) -> str:
    p = f["preview"]
    cells = [material, kind, env, f"{eta_i:g}", f"{r:g}", f"{c:g}",
             f"{p['mean']:.4f} / {p['p99']:.3f} / {p['max']:.2f} / {p['centre']:.4f} / {p['ring']:.3f}"]
    q = f.get("preview_rec709")
    cells.append(f"{q['mean']:.4f} / {q['p99']:.3f} / {q['max']:.2f}" if q else "")
    if env == "white_sky":
        twin = f.get("twin")
        cells.append(f"{twin['mean']:.4f} / {twin['centre']:.4f}" if twin else "")
        cells.append(f"{f['physics']['mean']:.3f} / {f['physics']['centre']:.3f} / {f['physics']['ring']:.3f}")
        cells.append(f"{f['fallback']['mean']:.2f} / {f['fallback']['centre']:.2f}")
    else:
        cells += ["", "", ""]
    return "| " + " | ".join(cells) + " |"


def _spread(fs: list[dict]) -> dict[str, float]:
    """Mean of the settings' means, the worst setting's mean and the worst pixel."""
    return {"mean": sum(f["mean"] for f in fs) / len(fs), "worst_mean": max(f["mean"] for f in fs),
            "worst_max": max(f["max"] for f in fs), "settings": len(fs)}


def figures(rows: list[tuple], environments: list[str]) -> dict:
    """The recorded figures: per environment (both kinds and each kind) against the preview, lit in
    Rec.709 where measured; under the white sky the twin, the physics per kind and the fallback."""
    out: dict = {"settings": len(rows), "vs_preview": {}, "vs_preview_lit_rec709": {}}
    for env in environments:
        for label, kinds in [("all", KINDS), *((kind, (kind,)) for kind in KINDS)]:
            of = [r[6] for r in rows if r[2] == env and r[1] in kinds]
            if of:
                out["vs_preview"].setdefault(env, {})[label] = _spread([f["preview"] for f in of])
            lit = [f["preview_rec709"] for f in of if "preview_rec709" in f]
            if lit:
                out["vs_preview_lit_rec709"].setdefault(env, {})[label] = _spread(lit)
    white = [r for r in rows if r[2] == "white_sky"]
    if white:
        twins = [r[6]["twin"] for r in white if r[6].get("twin")]
        if twins:
            out["twin"] = _spread(twins)
        out["physics"] = {kind: _spread([r[6]["physics"] for r in white if r[1] == kind])
                          for kind in KINDS if any(r[1] == kind for r in white)}
        fallback = [r[6]["fallback"]["mean"] for r in white]
        out["fallback"] = {"mean": sum(fallback) / len(fallback), "min": min(fallback), "max": max(fallback)}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--materials", default="Au,Cu,Cr,Al", help="comma-separated library materials")
    parser.add_argument("--environments", default=",".join(ENVIRONMENTS), help="comma-separated preview environments")
    parser.add_argument("--record", default=str(RECORD), help="file for the table ('-': none)")
    parser.add_argument("--result", default="three_parity",
                        help="name of the figures' record, benchmarks/results/NAME.json ('-': none)")
    args = parser.parse_args()
    environments = args.environments.split(",")
    rows = []
    started = time.perf_counter()
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data") as server:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 900, "height": 700})
            page.set_default_timeout(300_000)
            for material in args.materials.split(","):
                nk = library_material(material)
                for kind in KINDS:
                    fit = create_fit(server.url, material, kind)
                    for eta_i, lobes in SETTINGS:
                        open_example(page, server.url, fit["id"], eta_i, environments[0])
                        for env in environments:
                            for roughness, coat_roughness in lobes:
                                f = measure_three(page, server.url, nk, fit, eta_i, roughness, coat_roughness, env)
                                rows.append((material, kind, env, eta_i, roughness, coat_roughness, f))
                                print(f"{material} {kind} {env} {eta_i} {roughness} {coat_roughness}: "
                                      f"{f['preview']['mean']:.4f} / max {f['preview']['max']:.3f}", file=sys.stderr)
            browser.close()
    load = max(load, os.getloadavg()[0])
    lines = [
        "| material | kind | environment | eta_i | roughness | coat | vs preview: mean / p99 / max / centre / ring "
        "| vs preview lit in Rec.709: mean / p99 / max "
        "| vs twin: mean / centre | vs physics: mean / centre / ring | fallback vs physics: mean / centre |",
        "|---|---|---|---:|---:|---:|---|---|---|---|---|",
    ]
    lines += [_row(*row) for row in rows]
    for kind in KINDS:
        for env in environments:
            of = [row[6]["preview"] for row in rows if row[1] == kind and row[2] == env]
            lit = [row[6]["preview_rec709"] for row in rows if row[1] == kind and row[2] == env and "preview_rec709" in row[6]]
            if of:
                summary = lambda fs: (f"**mean {sum(f['mean'] for f in fs) / len(fs):.4f}**, worst mean "
                                      f"{max(f['mean'] for f in fs):.4f}, worst max {max(f['max'] for f in fs):.2f}")
                lines.append(f"| **{kind}** | | **{env}** | | | | {summary(of)} | {summary(lit) if lit else ''} | | | |")
    table = "\n".join(lines)
    print(table)
    if args.record != "-":
        path = Path(args.record)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(
            "# benchmarks/three_parity.py\n\n"
            f"Command: `.venv/bin/python benchmarks/three_parity.py --materials {args.materials} "
            f"--environments {args.environments}`; run {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
            f"load average up to {load:.1f} on {os.cpu_count()} cores.\n\n"
            "Delta E 2000, 128 x 128, Chromium (SwiftShader WebGL2), three "
            f"{three_version()} through EXT_materials_coated_conductor against the editor's WebGL "
            f"preview at the same settings (both kinds); {len(rows)} settings in "
            f"{time.perf_counter() - started:.0f} s. Under the studio and outdoor skies both sides "
            "draw the same cf_environment.glsl, filtered each its own way (three's PMREM, with its "
            "roughness floor of 0.0525; the preview's analytic mirror or the project's prefiltered "
            "slices), so those rows hold the filters' difference as well as the material's; and three "
            "multiplies albedo and radiance per channel in linear Rec.709, the preview in ACEScg: the "
            "column 'lit in Rec.709' recomposes the preview's own parts as three lights them "
            "(tests/static/three_pages.py preview_lit_in_rec709).\n\n"
            f"{table}\n"
        )
        print(f"recorded in {path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}", file=sys.stderr)
    if args.result != "-":
        path = write_result(args.result, figures(rows, environments), load, materials=args.materials.split(","),
                            seconds=round(time.perf_counter() - started), three=three_version())
        print(f"recorded in {path.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
