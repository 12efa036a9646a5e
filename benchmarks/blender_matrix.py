"""
Exports: the Blender versions
=============================

The Blender export rendered by each Blender release the project installs
(``bpy`` from the package registry: the pinned one in ``scripts/blender-env``
and the matrix in ``scripts/blender-matrix/<version>``, each in its own
environment ``.venv-blender`` / ``.venv-blender-<version>``), with Cycles on a
flat plane at the view angles 0, 10, ..., 80 degrees under a uniform white
world (``tests/fitting/exports/cycles_angles.py``, all exports of a version in
one Blender process), against the physical coat on the metal seen from air
(:func:`fitting.colour.seen.seen_ACEScg`): the seen mean and max Delta E 2000
per version, output (``principled``: the Principled BSDF, active;
``conductor``: the Metallic BSDF in Physical Conductor mode, where the script
makes it; ``conductor_ungated``: the same made in every release that has the
node, what the script's version gate keeps out) and coat index, next to the numpy mirror of Cycles' layering that
the values were fitted with (:func:`fitting.exports.seen_fidelity`).

    .venv/bin/python benchmarks/blender_matrix.py [--materials Au,Cu] [--eta-i 1.5,2.0] [--samples 32]

Records benchmarks/results/blender_matrix.json: per version (keyed
``blender_5_0_1``) and output the
mean over the metals and coat indices of the seen mean, the worst metal's
max, the largest difference from the mirror, and the rows.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
import time
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

METALS = "Au,Cu,Ag,Al,CuZn,Cr,Ni,W"
ETA_I = "1.0,1.5,2.0"
ANGLES_DEG = tuple(range(0, 81, 10))
CYCLES_ANGLES = ROOT / "tests" / "fitting" / "exports" / "cycles_angles.py"
TOOLS = {"principled": "blender", "conductor": "blender-conductor", "conductor_ungated": "blender-conductor"}
GATE = "CONDUCTOR_FROM = (5, 0, 0)"


def _pinned(project: Path) -> str:
    """The ``bpy`` version a Blender environment's project pins (``bpy==X.Y.Z``)."""
    text = (project / "pyproject.toml").read_text()
    return re.search(r'"bpy==([0-9.]+)"', text).group(1)


def blender_pythons() -> dict[str, Path]:
    """Blender release -> its environment's Python, oldest first (the pinned one included)."""
    found = {_pinned(ROOT / "scripts" / "blender-env"): ROOT / ".venv-blender" / "bin" / "python"}
    for project in sorted((ROOT / "scripts" / "blender-matrix").iterdir()):
        if (project / "pyproject.toml").exists():
            found[_pinned(project)] = ROOT / f".venv-blender-{project.name}" / "bin" / "python"
    return dict(sorted(found.items(), key=lambda kv: tuple(int(x) for x in kv[0].split("."))))


def render_many(python: Path, scripts: list[Path], samples: int, work: Path) -> dict:
    """{script path: {output: {angle: rgb} or {"error": message}}} from one Blender process."""
    if not python.exists():
        raise FileNotFoundError(f"{python} is missing: run scripts/bootstrap")
    result = subprocess.run(
        [
            str(python),
            str(CYCLES_ANGLES),
            *map(str, scripts),
            "--output",
            "principled,conductor",
            "--angles",
            ",".join(str(a) for a in ANGLES_DEG),
            "--samples",
            str(samples),
        ],
        capture_output=True,
        text=True,
        timeout=1800,
        cwd=work,
    )
    if result.returncode != 0:
        raise RuntimeError(result.stdout[-3000:] + result.stderr[-3000:])
    line = next(x for x in result.stdout.splitlines() if x.startswith("CYCLES_MANY "))
    return json.loads(line.split(" ", 1)[1])


def seen_error(nk, values, rgb_by_angle: dict) -> tuple[float, float]:
    """Seen mean and max Delta E of Cycles' pixels at ANGLES_DEG against the physical coat."""
    pixels = np.array([rgb_by_angle[f"{a:g}"] for a in ANGLES_DEG], dtype=np.float64)
    seen = seen_ACEScg(nk, np.cos(np.radians(ANGLES_DEG)), values.eta_i)
    errors = delta_E_map(seen, working_to_ACEScg(pixels, values.working_space))
    return float(errors.mean()), float(errors.max())


def measure(materials: list[str], etas: list[float], samples: int, ungated: bool = True) -> dict:
    """{version: {"rows": [...], "wall_s": s}}; ``ungated``: also the conductor made in every release."""
    exports = {}
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        scripts = []
        for metal in materials:
            nk = library_material(metal)
            for eta in etas:
                values = export_values(nk, eta, roughness=0.0, coat_roughness=0.0, tools=tuple(TOOLS.values()))
                text = export_material(values, "blender", eta).decode()
                script, twin = work / f"{metal}_{eta:g}.py", work / f"{metal}_{eta:g}_ungated.py"
                script.write_text(text)
                exports[str(script)] = (metal, eta, nk, values, str(twin))
                scripts.append(script)
                if not ungated:
                    continue
                # The same script with the Physical Conductor made in every release: what
                # the gate keeps out of the older ones.
                assert GATE in text, "the script's version gate moved: update GATE"
                twin.write_text(text.replace(GATE, "CONDUCTOR_FROM = (0, 0, 0)"))
                scripts.append(twin)
        versions = {}
        for version, python in blender_pythons().items():
            start = time.perf_counter()
            rendered = render_many(python, scripts, samples, work)
            rows = []
            for script, (metal, eta, nk, values, twin) in exports.items():
                for output, tool in TOOLS.items():
                    if output == "conductor_ungated" and not ungated:
                        continue
                    got = rendered[twin]["conductor"] if output == "conductor_ungated" else rendered[script][output]
                    mirror = seen_fidelity(values, tool)
                    row = {
                        "material": metal,
                        "eta_i": eta,
                        "output": output,
                        "mirror_mean": round(mirror["delta_E_mean"], 4),
                    }
                    if "error" in got:
                        row["absent"] = got["error"]
                    else:
                        mean, worst = seen_error(nk, values, got)
                        row.update(seen_mean=round(mean, 4), seen_max=round(worst, 4))
                    rows.append(row)
            versions[version] = {"rows": rows, "wall_s": round(time.perf_counter() - start, 1)}
            print(version, json.dumps(summary(rows)), flush=True)
    return versions


def summary(rows: list[dict]) -> dict:
    """Per output: mean of the seen means, worst max, largest |seen - mirror|, or that it is absent."""
    out = {}
    for output in TOOLS:
        mine = [r for r in rows if r["output"] == output]
        drawn = [r for r in mine if "seen_mean" in r]
        if not drawn:
            out[output] = {"absent": mine[0]["absent"] if mine else "not rendered"}
            continue
        worst = max(drawn, key=lambda r: r["seen_max"])
        out[output] = {
            "seen_mean": round(float(np.mean([r["seen_mean"] for r in drawn])), 3),
            "seen_max": round(worst["seen_max"], 3),
            "worst": f"{worst['material']} at {worst['eta_i']:g}",
            "largest_from_mirror": round(max(abs(r["seen_mean"] - r["mirror_mean"]) for r in drawn), 3),
            "exports": len(drawn),
        }
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/blender_matrix.py")
    parser.add_argument("--materials", default=METALS)
    parser.add_argument("--eta-i", default=ETA_I)
    parser.add_argument("--samples", type=int, default=32)
    args = parser.parse_args(argv)
    load = load_average()
    versions = measure(args.materials.split(","), [float(x) for x in args.eta_i.split(",")], args.samples)
    # Keyed "blender_5_0_1" (the docs' figure markers take dotted paths).
    figures = {"blender_" + version.replace(".", "_"): summary(data["rows"]) for version, data in versions.items()}
    write_result(
        "blender_matrix",
        figures,
        load,
        what="seen Delta E 2000 of the Blender export rendered by each Blender release (Cycles, plane, "
        "white world, view angles 0-80 deg), per output; the mirror is the fit's own figure",
        materials=args.materials,
        eta_i=args.eta_i,
        samples=args.samples,
        angles_deg=list(ANGLES_DEG),
        versions=versions,
    )
    print(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
