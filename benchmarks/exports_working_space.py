"""
Exports in an ACEScg host
=========================

Each export fitted and written in each working space
(``fitting.exports.colour_space.WORKING_SPACES``), and what the user sees in
the tool working in that space, against the physical coat on the metal seen
from air (:func:`fitting.colour.seen.seen_ACEScg`), Delta E 2000 over the
view angles, roughness 0, a uniform white sky, coat index ``--eta-i``:

-   ``materialx``: the ``mtlx`` and ``openpbr`` documents rendered with the
    GLSL MaterialX generates for them (:mod:`preview_shaders.materialx_render`).
    A ``lin_rec709`` document in a ``lin_rec709`` host (no colour management);
    an ``acescg`` document with MaterialX's own colour management and the
    target ``acescg`` (``targetColorSpaceOverride``), as an ACEScg host
    generates it; and, for contrast, each document in the other host: the
    ``lin_rec709`` document with the target ``acescg`` (MaterialX's default
    colour management has no transform to ``acescg``: its values are taken
    as ACEScg), and the ``acescg`` document with the target ``lin_rec709``
    (MaterialX converts every colour input, the conductor's n and k too). Mean over the sphere's pixels within 1 degree of each of
    the view angles 0, 10, ..., 80 (each against the seen target at its
    own cos theta).
-   ``cycles``: the Blender export's two outputs rendered by Cycles
    (``.venv-blender``, ``tests/fitting/exports/cycles_angles.py``) in a
    file whose working space is the export's (``--working-space acescg``
    makes the file ACEScg, Blender 5), at the same angles, ``--samples``.
-   ``mirrors``: the numpy mirrors' seen mean (the fit's own figure) per tool.

    .venv/bin/python benchmarks/exports_working_space.py [--materials Au,Cu] [--eta-i 1.5]

Records benchmarks/results/exports_working_space.json: per tool and host
the mean over the metals of the seen mean Delta E, the largest difference
between a metal's ACEScg and Rec.709 figure, and the rows per metal.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from fitting.colour.delta_e import delta_E_map  # noqa: E402
from fitting.colour.seen import seen_ACEScg  # noqa: E402
from fitting.exports import export_material, export_values, seen_fidelity  # noqa: E402
from fitting.exports.colour_space import working_to_ACEScg  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from preview_shaders.gl import RenderThread  # noqa: E402
from preview_shaders.materialx_render import render_materialx  # noqa: E402
from preview_shaders.preview import sphere_cos_theta  # noqa: E402

METALS = "Au,Cu,Ag,Al,CuZn,Cr,Ni,W"
ANGLES_DEG = tuple(range(0, 81, 10))
SIZE = 96
BLENDER_PYTHON = ROOT / ".venv-blender" / "bin" / "python"
CYCLES_ANGLES = ROOT / "tests" / "fitting" / "exports" / "cycles_angles.py"
TOOLS = ("mtlx", "openpbr", "blender", "blender-conductor")


def materialx_mean(nk, values, fmt: str, target, thread) -> float:
    """Seen mean Delta E of a MaterialX render (pixels in ``target``, or the document's space when None)."""
    image, _ = render_materialx(
        export_material(values, fmt, values.eta_i).decode(), SIZE, thread, target_colorspace=target
    )
    space = target or values.working_space
    mu, mask = sphere_cos_theta(SIZE)
    theta = np.degrees(np.arccos(np.clip(mu, 0.0, 1.0)))
    means = []
    for angle in ANGLES_DEG:
        at = mask & (np.abs(theta - angle) <= 1.0)
        seen = seen_ACEScg(nk, mu[at], values.eta_i)
        means.append(float(delta_E_map(seen, working_to_ACEScg(image[at].astype(np.float64), space)).mean()))
    return float(np.mean(means))


def cycles_mean(nk, values, output: str, samples: int, work: Path) -> float:
    """Seen mean Delta E of Cycles' render of the Blender export in a file of the export's working space."""
    script = work / f"{values.name}-{values.working_space}.py"
    script.write_bytes(export_material(values, "blender", values.eta_i))
    result = subprocess.run(
        [
            str(BLENDER_PYTHON),
            str(CYCLES_ANGLES),
            str(script),
            "--output",
            output,
            "--angles",
            ",".join(str(a) for a in ANGLES_DEG),
            "--samples",
            str(samples),
            "--working-space",
            values.working_space,
        ],
        check=True,
        capture_output=True,
        text=True,
        timeout=900,
    )
    line = next(x for x in result.stdout.splitlines() if x.startswith("CYCLES_ANGLES "))
    rgb = json.loads(line.split(" ", 1)[1])
    pixels = np.array([rgb[f"{a:g}"] for a in ANGLES_DEG], dtype=np.float64)
    seen = seen_ACEScg(nk, np.cos(np.radians(ANGLES_DEG)), values.eta_i)
    return float(delta_E_map(seen, working_to_ACEScg(pixels, values.working_space)).mean())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/exports_working_space.py")
    parser.add_argument("--materials", default=METALS)
    parser.add_argument("--eta-i", type=float, default=1.5)
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--no-cycles", action="store_true", help="skip the Cycles renders")
    args = parser.parse_args(argv)
    load = load_average()
    rows = {}
    with RenderThread("exports-working-space") as thread, tempfile.TemporaryDirectory() as tmp:
        for metal in args.materials.split(","):
            nk = library_material(metal)
            row = {}
            for space in ("lin_rec709", "acescg"):
                values = export_values(
                    nk, args.eta_i, roughness=0.0, coat_roughness=0.0, tools=TOOLS, working_space=space
                )
                for tool in TOOLS:
                    row[f"mirror_{tool}_{space}"] = seen_fidelity(values, tool)["delta_E_mean"]
                for fmt in ("mtlx", "openpbr"):
                    target = "acescg" if space == "acescg" else None
                    row[f"materialx_{fmt}_{space}"] = materialx_mean(nk, values, fmt, target, thread)
                    other = "lin_rec709" if space == "acescg" else "acescg"
                    row[f"materialx_{fmt}_{space}_in_{other}_host"] = materialx_mean(nk, values, fmt, other, thread)
                if not args.no_cycles:
                    for output, tool in (("principled", "blender"), ("conductor", "blender-conductor")):
                        row[f"cycles_{tool}_{space}"] = cycles_mean(nk, values, output, args.samples, Path(tmp))
            rows[metal] = row
            print(metal, json.dumps({k: round(v, 3) for k, v in row.items()}), flush=True)
    first = next(iter(rows.values()))
    keys = sorted({k[: -len("_lin_rec709")] for k in first if k.endswith("_lin_rec709")})
    figures = {}
    for key in keys:
        rec, aces = (np.array([r[f"{key}_{s}"] for r in rows.values()]) for s in ("lin_rec709", "acescg"))
        figures[key] = {
            "lin_rec709_mean": round(float(rec.mean()), 3),
            "lin_rec709_max": round(float(rec.max()), 3),
            "acescg_mean": round(float(aces.mean()), 3),
            "acescg_max": round(float(aces.max()), 3),
            # ACEScg minus Rec.709 per metal: the most it is worse, and the largest change either way.
            "largest_worsening": round(float(np.max(aces - rec)), 3),
            "largest_difference": round(float(np.max(np.abs(aces - rec))), 3),
        }
        for space, other in (("lin_rec709", "acescg"), ("acescg", "lin_rec709")):
            cross = f"{key}_{space}_in_{other}_host"
            if cross in first:
                figures[key][f"{space}_document_in_{other}_host_mean"] = round(
                    float(np.mean([r[cross] for r in rows.values()])), 3
                )
    for key, value in figures.items():
        print(f"{key}: {value}")
    path = write_result(
        "exports_working_space",
        figures,
        load,
        eta_i=args.eta_i,
        materials=args.materials.split(","),
        samples=args.samples,
        rows=rows,
    )
    print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
