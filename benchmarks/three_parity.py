"""
three.js through EXT_materials_coated_conductor against the preview and the physics
===================================================================================

For each library material, model kind and setting (coat index eta_i, metal
roughness, coat roughness): a fit stored on a server just started, its glTF
export loaded on /examples/three.html with the plugin and without it, and
both balls read back as float radiance in Chromium (SwiftShader WebGL2)
under the white sky, 128 x 128, against

-   the editor's WebGL preview at the same settings (coated-conductor; the
    preview has no rgb-conductor band, so that kind is compared with numpy's
    twin of the same material: split sum of its exact Fresnel, the same
    coat);
-   the physics: the 1 nm spectral reference under the coat in the coated
    split sum (tests/static/three_pages.py);
-   the fallback ball (no plugin: Schlick base colour and
    KHR_materials_clearcoat) against the same physics.

Mean Delta E 2000 over the ball's pixels with NdotV >= 0.1, its 99th
percentile, the mean at the centre (NdotV >= 0.97) and on the ring near
grazing (NdotV in [0.1, 0.25]). Prints a Markdown table and records it::

    .venv/bin/python benchmarks/three_parity.py            # about 8 min here
    .venv/bin/python benchmarks/three_parity.py --materials Au --record -
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "static"))

from conftest import server_process  # noqa: E402
from editor_pages import CHROMIUM_ARGS  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402
from three_pages import create_fit, measure_three, open_example  # noqa: E402

from fitting.models.kinds import MODEL_KINDS, model_kind  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402

SETTINGS = [(1.5, 0.0, 0.0), (1.5, 0.3, 0.1), (2.2, 0.5, 0.2)]
KINDS = tuple(MODEL_KINDS)
RECORD = ROOT / "benchmarks" / "records" / "three_parity.md"


def three_version() -> str:
    """three's version as scripts/three/package-lock.json pins it."""
    lock = json.loads((ROOT / "scripts" / "three" / "package-lock.json").read_text())
    return lock["packages"]["node_modules/three"]["version"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--materials", default="Au,Cu,Cr,Al", help="comma-separated library materials")
    parser.add_argument("--record", default=str(RECORD), help="file for the table ('-': none)")
    args = parser.parse_args()
    rows = []
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data") as server:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 900, "height": 700})
            page.set_default_timeout(300_000)
            for material in args.materials.split(","):
                nk = library_material(material)
                for kind in KINDS:
                    fit = create_fit(server.url, material, kind)
                    for eta_i, roughness, coat_roughness in SETTINGS:
                        open_example(page, server.url, fit["id"], eta_i)
                        f = measure_three(page, server.url, nk, fit, eta_i, roughness, coat_roughness)
                        parity = f.get("preview", f.get("twin"))
                        rows.append((material, kind, eta_i, roughness, coat_roughness, parity, f["physics"], f["fallback"]))
                        print(f"{material} {kind} {eta_i} {roughness} {coat_roughness}: "
                              f"{parity['mean']:.4f} / {f['physics']['mean']:.4f} / {f['fallback']['mean']:.3f}",
                              file=sys.stderr)
            browser.close()
    lines = [
        "| material | kind | eta_i | roughness | coat | vs preview (twin): mean / p99 / centre / ring "
        "| vs physics: mean / centre / ring | fallback vs physics: mean / centre |",
        "|---|---|---:|---:|---:|---|---|---|",
    ]
    for material, kind, eta_i, r, c, parity, physics, fallback in rows:
        # A kind the rough preview cannot draw (no split sum) is compared with its twin.
        versus = "preview" if model_kind(kind).split_sum else "twin"
        lines.append(
            f"| {material} | {kind} | {eta_i:g} | {r:g} | {c:g} | {versus} {parity['mean']:.4f} / "
            f"{parity['p99']:.3f} / {parity['centre']:.4f} / {parity['ring']:.3f} | {physics['mean']:.3f} / "
            f"{physics['centre']:.3f} / {physics['ring']:.3f} | {fallback['mean']:.2f} / {fallback['centre']:.2f} |"
        )
    for kind in KINDS:
        of = [row for row in rows if row[1] == kind]
        if of:
            lines.append(
                f"| **mean, {kind}** | | | | | **{sum(r[5]['mean'] for r in of) / len(of):.4f}** "
                f"(max of means {max(r[5]['mean'] for r in of):.4f}) | **{sum(r[6]['mean'] for r in of) / len(of):.3f}** "
                f"| {sum(r[7]['mean'] for r in of) / len(of):.2f} |"
            )
    table = "\n".join(lines)
    print(table)
    if args.record != "-":
        path = Path(args.record)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(
            "# benchmarks/three_parity.py\n\n"
            "Delta E 2000, 128 x 128, white sky, Chromium (SwiftShader WebGL2), three "
            f"{three_version()} through EXT_materials_coated_conductor; "
            f"{len(rows)} settings in {time.perf_counter() - started:.0f} s.\n\n{table}\n"
        )
        print(f"recorded in {path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}", file=sys.stderr)


if __name__ == "__main__":
    main()
