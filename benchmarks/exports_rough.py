"""
Exports on a rough metal: the view-dependent index against the constant one
===========================================================================

The conductor exports drive n and k by the view angle at the shading normal
(N.V), while on a rough metal the tool takes each microfacet's Fresnel at
its own half-vector angle. The view-dependent index is fitted at roughness
0 only. This measures what it does on a rough metal, in Cycles (the Blender
export's Physical Conductor output, a plane under a uniform white world,
``tests/fitting/exports/cycles_angles.py``), for W and CuZn at eta_i 1.5:

-   ``shipped``: the export as written (index affine in 1 - cos theta);
-   ``constant``: the same export with the constant fit (slopes 0), the
    conductor export before the view-dependent index;

each against a reference of the physics: Mitsuba 3
(``scalar_spectral_polarized``, the set-up that
``tests/fitting/optics/test_coated_stack.py`` checks against the seen
model at roughness 0): a smooth dielectric rectangle of index eta_i 1e-3
above a GGX ``roughconductor`` (alpha = roughness^2, the measured n, k / eta_i
per wavelength), under a constant D65 sky, orthographic camera at the view
angle, the ratio to the sky's own render per channel (linear Rec.709). At
roughness 0 (``conductor``) the same reference is compared with the seen
model (``reference_vs_seen``): the reference's own colour pipeline error.

    .venv/bin/python benchmarks/exports_rough.py [--roughness 0.3] [--samples 128]

Records benchmarks/results/exports_rough.json.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
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
from fitting.exports import export_material, export_values  # noqa: E402
from fitting.exports.colour_space import lin_rec709_to_ACEScg  # noqa: E402
from fitting.exports.seen_fit import fit_tool_values  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402

ETA = 1.5
METALS = ("W", "CuZn")
ANGLES = (0.0, 40.0, 70.0, 80.0)
BLENDER_PYTHON = ROOT / ".venv-blender" / "bin" / "python"
CYCLES_ANGLES = ROOT / "tests" / "fitting" / "exports" / "cycles_angles.py"
MITSUBA_SPP = 16384  # the noise of test_coated_stack's check: about 3e-4 on R


_SKY: dict = {}


def mitsuba_reflectance(nk, alpha: float | None, theta: float) -> np.ndarray:
    """The reference's linear Rec.709 reflectance at view angle ``theta`` (alpha None: smooth)."""
    import mitsuba as mi

    mi.set_variant("scalar_spectral_polarized")
    keep = (nk.wavelength_nm >= 360.0) & (nk.wavelength_nm <= 830.0)
    wl = ", ".join(f"{w:.6g}" for w in nk.wavelength_nm[keep])

    def spectrum(values):
        return {"type": "irregular", "wavelengths": wl, "values": ", ".join(f"{v:.6g}" for v in values)}

    def scene(with_metal: bool):
        direction = np.array([np.sin(np.radians(theta)), 0.0, np.cos(np.radians(theta))])
        T = mi.ScalarTransform4f()
        d = {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 64, "rr_depth": 1000},
            "sensor": {
                "type": "orthographic",
                "to_world": T.look_at(origin=(5 * direction).tolist(), target=[0, 0, 0], up=[0, 1, 0])
                @ T.scale([0.01, 0.01, 1.0]),
                "film": {"type": "hdrfilm", "width": 4, "height": 4, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                "sampler": {"type": "independent", "sample_count": MITSUBA_SPP},
            },
            "sky": {"type": "constant", "radiance": {"type": "d65"}},
        }
        if with_metal:
            bsdf = {"eta": spectrum(nk.n[keep] / ETA), "k": spectrum(nk.k[keep] / ETA)}
            bsdf.update(
                {"type": "conductor"}
                if alpha is None
                else {"type": "roughconductor", "distribution": "ggx", "alpha": alpha}
            )
            d["metal"] = {"type": "rectangle", "to_world": T.translate([0, 0, -1e-3]) @ T.scale(100.0), "bsdf": bsdf}
            d["coat"] = {
                "type": "rectangle",
                "to_world": T.scale(100.0),
                "bsdf": {"type": "dielectric", "int_ior": ETA, "ext_ior": 1.0},
            }
        return mi.load_dict(d)

    if theta not in _SKY:
        _SKY[theta] = np.array(mi.render(scene(False)), dtype=np.float64).reshape(-1, 3).mean(axis=0)
    lit = np.array(mi.render(scene(True)), dtype=np.float64).reshape(-1, 3).mean(axis=0)
    return lit / _SKY[theta]


def cycles(values, samples: int) -> np.ndarray:
    """Cycles' render of the Blender export's Physical Conductor output, (angles, 3) linear Rec.709."""
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "export.py"
        script.write_bytes(export_material(values, "blender", ETA))
        result = subprocess.run(
            [
                str(BLENDER_PYTHON),
                str(CYCLES_ANGLES),
                str(script),
                "--output",
                "conductor",
                "--angles",
                ",".join(f"{a:g}" for a in ANGLES),
                "--samples",
                str(samples),
            ],
            capture_output=True,
            text=True,
            timeout=900,
            cwd=tmp,
            check=True,
        )
    line = [ln for ln in result.stdout.splitlines() if ln.startswith("CYCLES_ANGLES ")][-1]
    rendered = json.loads(line.split(" ", 1)[1])
    return np.array([rendered[f"{a:g}"] for a in ANGLES])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/exports_rough.py")
    parser.add_argument("--roughness", type=float, default=0.3)
    parser.add_argument("--samples", type=int, default=128)
    parser.add_argument("--no-record", action="store_true")
    args = parser.parse_args(argv)
    started, load = time.time(), load_average()
    mu = np.cos(np.radians(ANGLES))
    figures = {}
    for name in METALS:
        nk = library_material(name)
        ref0 = np.array([mitsuba_reflectance(nk, None, a) for a in ANGLES])
        ref = np.array([mitsuba_reflectance(nk, args.roughness**2, a) for a in ANGLES])
        seen = seen_ACEScg(nk, mu, ETA)
        row = {"reference_vs_seen": delta_E_map(seen, lin_rec709_to_ACEScg(ref0)).tolist()}
        for rough in (0.0, args.roughness):
            values = export_values(nk, ETA, roughness=rough, coat_roughness=0.0, tools=("blender", "blender-conductor"))
            constant = fit_tool_values(
                "blender-conductor", values.view_cos, ETA, values.seen_ACEScg, view_dependent=False
            )
            flat = dataclasses.replace(values, tools={**values.tools, "blender-conductor": constant})
            target = lin_rec709_to_ACEScg(ref if rough else ref0)
            key = f"roughness_{rough:g}".replace(".", "_")
            row[key] = {}
            for label, v in (("shipped", values), ("constant", flat)):
                dE = delta_E_map(target, lin_rec709_to_ACEScg(cycles(v, args.samples)))
                row[key][label] = dE.tolist()
                row[key][label + "_mean"] = float(dE.mean())
                print(
                    f"{name} roughness {rough:g} {label}: Delta E at {ANGLES} = {np.round(dE, 3)}, "
                    f"mean {dE.mean():.3f}",
                    flush=True,
                )
        print(f"{name} reference vs seen model (roughness 0): {np.round(row['reference_vs_seen'], 3)}")
        figures[name] = row
    elapsed = time.time() - started
    print(f"{elapsed:.0f} s")
    if not args.no_record:
        write_result(
            "exports_rough",
            figures,
            load,
            angles_deg=list(ANGLES),
            roughness=args.roughness,
            samples=args.samples,
            mitsuba_spp=MITSUBA_SPP,
            eta_i=ETA,
            seconds=round(elapsed, 1),
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
