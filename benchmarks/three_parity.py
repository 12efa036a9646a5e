"""
three.js through EXT_materials_coated_conductor against the full stack, the preview and the physics
===================================================================================================

For each library material and model kind, a fit stored on a server just
started, its glTF export shown on /examples/three.html with the plugin and
without it (one page for the run: each fit and coat index put on it with
``cfThree.setFit``), both balls read back as float radiance in Chromium
(SwiftShader WebGL2), 128 x 128:

-   **smooth** (metal and coat mirrors) under the white sky at every coat
    index of :data:`SMOOTH_ETAS` (1.0 to 2.0), against the same fit composed
    with the full air-coat-metal stack in numpy (the coat's reflection,
    refraction, the model at the refracted angle, the bounces between coat
    and metal: ``composed``), the physics (the 1 nm spectral reference
    through the same stack), the fit's own error there (composed against
    physics) and the fallback ball against the physics;
-   **rough** (materials of ``--rough-materials``) at eta_i 1.5 and 2.2:
    the same under the white sky at the rough settings of
    :data:`ROUGH_SETTINGS`, where the plugin's approximation of the bounces
    for a rough metal is what numpy composes too; and under the studio and
    outdoor skies against the editor's preview, its parts composed as three
    lights them with the same stack (``preview_rec709``), and as the
    preview draws them (``preview``, no bounces: the size of the bounces).

Mean Delta E 2000 over the ball's pixels with NdotV >= 0.1, its 99th
percentile, its max, the mean at the centre (NdotV >= 0.97) and on the ring
near grazing (NdotV in [0.1, 0.25]). Prints a Markdown table and records it::

    .venv/bin/python benchmarks/three_parity.py --materials Ag,Al,Au,Cu,Cr,CuZn --rough-materials Au,Cu   # about 35 min here, loaded
    .venv/bin/python benchmarks/three_parity.py --materials Au --rough-materials Au --record - --result -
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
from three_pages import create_fit, measure_three, open_example, show_fit  # noqa: E402

from fitting.models.kinds import MODEL_KINDS  # noqa: E402
from fitting.optics.library import LIBRARY_NAMES, library_material  # noqa: E402

SMOOTH_ETAS = (1.0, 1.33, 1.5, 2.0)
# (eta_i, [(metal roughness, coat roughness), ...]) of the rough materials, white sky.
ROUGH_SETTINGS = [(1.5, [(0.3, 0.0), (0.3, 0.1)]), (2.2, [(0.5, 0.2)])]
# (eta_i, (metal roughness, coat roughness), environment) of the rough materials, coloured skies.
SKY_SETTINGS = [(1.5, (0.3, 0.1), "studio"), (1.5, (0.3, 0.1), "outdoor")]
# The fit's own error below which the plugin must be within PHYSICS_BOUND of the physics.
FIT_ERROR_BELOW, PHYSICS_BOUND = 0.2, 0.3
KINDS = tuple(MODEL_KINDS)
RECORD = ROOT / "benchmarks" / "records" / "three_stack.md"


def three_version() -> str:
    """three's version as scripts/three/package-lock.json pins it."""
    lock = json.loads((ROOT / "scripts" / "three" / "package-lock.json").read_text())
    return lock["packages"]["node_modules/three"]["version"]


def _cell(f: dict | None, keys=("mean", "max"), fmt=".3f") -> str:
    return " / ".join(format(f[k], fmt) for k in keys) if f else ""


def _row(material, kind, env, eta_i, r, c, f) -> str:
    cells = [
        material,
        kind,
        env,
        f"{eta_i:g}",
        f"{r:g}",
        f"{c:g}",
        _cell(f.get("composed"), ("mean", "p99", "max", "centre", "ring"), ".4f"),
        _cell(f.get("physics"), ("mean", "centre", "ring")),
        _cell(f.get("fit_vs_physics"), ("mean",)),
        _cell(f.get("fallback"), ("mean", "centre")),
        _cell(f["preview"] if env == "white_sky" else f.get("preview_rec709"), ("mean", "p99", "max"), ".4f"),
        _cell(f.get("preview_bare") if env == "white_sky" else f["preview"], ("mean", "max")),
    ]
    return "| " + " | ".join(cells) + " |"


def _spread(fs: list[dict]) -> dict[str, float]:
    """Mean of the settings' means, the worst setting's mean and the worst pixel."""
    return {
        "mean": sum(f["mean"] for f in fs) / len(fs),
        "worst_mean": max(f["mean"] for f in fs),
        "worst_max": max(f["max"] for f in fs),
        "settings": len(fs),
    }


def _by_kind(rows: list[tuple], name: str) -> dict:
    out = {}
    for label, kinds in [("all", KINDS), *((kind, (kind,)) for kind in KINDS)]:
        of = [r[6][name] for r in rows if r[1] in kinds and name in r[6]]
        if of:
            out[label] = _spread(of)
    return out


def figures(rows: list[tuple]) -> dict:
    """
    The recorded figures. ``smooth``: against the fit composed with the full
    stack, the physics (all, and where the fit's own error is below
    FIT_ERROR_BELOW), the fallback, and how often the plugin is further from
    the physics than the fallback; ``rough``: the same under the white sky
    and, under each coloured sky, the preview lit in Rec.709 with the stack
    and as it draws.
    """
    smooth = [r for r in rows if r[2] == "white_sky" and r[4] == 0 and r[5] == 0]
    rough = [r for r in rows if r[2] == "white_sky" and (r[4] or r[5])]
    out: dict = {"settings": len(rows), "smooth_settings": len(smooth), "materials": len({r[0] for r in rows})}
    for label, of in [("smooth", smooth), ("rough", rough)]:
        if not of:
            continue
        good = [r for r in of if r[6]["fit_vs_physics"]["mean"] < FIT_ERROR_BELOW]
        worse = [r for r in of if r[6]["physics"]["mean"] > r[6]["fallback"]["mean"]]
        out[label] = {
            "composed": _by_kind(of, "composed"),
            "physics": _by_kind(of, "physics"),
            "fit_vs_physics": _by_kind(of, "fit_vs_physics"),
            "fallback": _by_kind(of, "fallback"),
            "preview": _by_kind(of, "preview"),
            "preview_bare": _by_kind(of, "preview_bare"),
            "physics_where_fit_good": _spread([r[6]["physics"] for r in good]) if good else None,
            "fit_good_settings": len(good),
            "worse_than_fallback": len(worse),
            "least_margin_to_fallback": min(r[6]["fallback"]["mean"] - r[6]["physics"]["mean"] for r in of),
        }
    for env in sorted({r[2] for r in rows} - {"white_sky"}):
        of = [r for r in rows if r[2] == env]
        out[env] = {"preview_rec709": _by_kind(of, "preview_rec709"), "preview": _by_kind(of, "preview")}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--materials", default=",".join(LIBRARY_NAMES), help="comma-separated library materials")
    parser.add_argument(
        "--rough-materials",
        default="Au,Cu,Cr,Al",
        help="comma-separated materials also measured rough and under the coloured skies",
    )
    parser.add_argument("--record", default=str(RECORD), help="file for the table ('-': none)")
    parser.add_argument(
        "--result", default="three_stack", help="name of the figures' record, benchmarks/results/NAME.json ('-': none)"
    )
    args = parser.parse_args()
    materials = args.materials.split(",")
    rough_materials = [m for m in args.rough_materials.split(",") if m]
    rows = []
    started = time.perf_counter()
    load = os.getloadavg()[0]

    def measure(page, nk, fit, eta_i, roughness, coat_roughness, env, material, kind):
        f = measure_three(page, server.url, nk, fit, eta_i, roughness, coat_roughness, env)
        rows.append((material, kind, env, eta_i, roughness, coat_roughness, f))
        key = "composed" if env == "white_sky" else "preview_rec709"
        print(
            f"{material} {kind} {env} {eta_i} {roughness} {coat_roughness}: {key} "
            f"{f[key]['mean']:.4f}"
            + (
                f", physics {f['physics']['mean']:.3f}, fallback {f['fallback']['mean']:.3f}"
                if env == "white_sky"
                else ""
            ),
            file=sys.stderr,
        )

    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data") as server:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 900, "height": 700})
            page.set_default_timeout(300_000)
            opened = False
            for material in materials:
                nk = library_material(material)
                for kind in KINDS:
                    fit = create_fit(server.url, material, kind)
                    plan = [(eta, [((0.0, 0.0), "white_sky")]) for eta in SMOOTH_ETAS]
                    if material in rough_materials:
                        plan += [(eta, [(lobe, "white_sky") for lobe in lobes]) for eta, lobes in ROUGH_SETTINGS]
                        plan += [(eta, [(lobe, env)]) for eta, lobe, env in SKY_SETTINGS]
                    for eta_i, lobes in plan:
                        if opened:
                            show_fit(page, fit["id"], eta_i)
                        else:
                            open_example(page, server.url, fit["id"], eta_i, "white_sky")
                            opened = True
                        for (roughness, coat_roughness), env in lobes:
                            measure(page, nk, fit, eta_i, roughness, coat_roughness, env, material, kind)
            browser.close()
    load = max(load, os.getloadavg()[0])
    lines = [
        "| material | kind | environment | eta_i | roughness | coat | vs the fit through the full stack: "
        "mean / p99 / max / centre / ring | vs physics: mean / centre / ring | the fit's own error: mean "
        "| fallback vs physics: mean / centre | vs the preview's parts through the stack (lit in Rec.709): "
        "mean / p99 / max | vs the preview as it draws (no bounces): mean / max |",
        "|---|---|---|---:|---:|---:|---|---|---|---|---|---|",
    ]
    lines += [_row(*row) for row in rows]
    table = "\n".join(lines)
    print(table)
    summary = figures(rows)
    if args.record != "-":
        path = Path(args.record)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(
            "# benchmarks/three_parity.py\n\n"
            f"Command: `.venv/bin/python benchmarks/three_parity.py --materials {args.materials} "
            f"--rough-materials {args.rough_materials}`; run {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
            f"load average up to {load:.1f} on {os.cpu_count()} cores.\n\n"
            "Delta E 2000, 128 x 128, Chromium (SwiftShader WebGL2), three "
            f"{three_version()} through EXT_materials_coated_conductor; {len(rows)} settings in "
            f"{time.perf_counter() - started:.0f} s. Under the white sky against the same fit composed with "
            "the full air-coat-metal stack in numpy (tests/static/three_pages.py coated_albedo: exact for "
            "mirrors, the plugin's approximation of the bounces for a rough metal), the physics through the "
            "same stack, and the preview's own parts through it. Under the studio and outdoor skies both "
            "draw the same cf_environment.glsl, filtered each its own way (three's PMREM, with its "
            "roughness floor of 0.0525; the preview's prefiltered slices), and three multiplies albedo and "
            "radiance per channel in linear Rec.709, the preview in ACEScg: the column 'lit in Rec.709' "
            "recomposes the preview's own parts as three lights them, with the bounces.\n\n"
            f"{table}\n"
        )
        print(f"recorded in {path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}", file=sys.stderr)
    if args.result != "-":
        path = write_result(
            args.result,
            summary,
            load,
            materials=materials,
            rough_materials=rough_materials,
            seconds=round(time.perf_counter() - started),
            three=three_version(),
        )
        print(f"recorded in {path.relative_to(ROOT)}", file=sys.stderr)
    else:
        print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
