"""
Exports: the pictures of docs/exports.md
========================================

Two figures, small (the machine has two shared cores):

-   ``docs/images/exports_cycles.png``: Cycles (Blender's ``bpy`` module, CPU,
    ``--samples`` samples, ``--size`` pixels) renders of a sphere, one row per
    material: the Blender export's Principled BSDF output, its Metallic BSDF
    (Physical Conductor) output, and the glTF export imported with Blender's
    glTF importer; a checkered environment so the reflections show.
-   ``docs/images/exports_white_sky.png``: the base Fresnel of each export as
    its tool evaluates it (:mod:`fitting.exports.tool_fresnel`) on the
    project's preview sphere under a uniform white sky (the paper's
    validation setting, where a pixel shows F(cos theta) at its cos theta):
    spectral reference, ``mtlx`` (conductor at the relative index),
    ``openpbr`` (F82 tint), ``gltf`` (Schlick).
-   ``docs/images/exports_materialx.png``: the ``mtlx`` and ``openpbr``
    documents rendered with the GLSL MaterialX generates for them, on the
    project's EGL context (:mod:`preview_shaders.materialx_render`; MaterialX's
    own GLSL renderer needs an X display) under a uniform white environment,
    next to the spectral reference on the same sphere; coat included.

    .venv/bin/python benchmarks/exports_renders.py [--materials Au,Cu] [--eta-i 1.5]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fitting.exports import export_material, export_values, tool_curve  # noqa: E402
from fitting.exports.colour_space import lin_rec709_to_ACEScg  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402
from preview_shaders.display import ACEScg_to_sRGB, to_uint8  # noqa: E402
from preview_shaders.gl import RenderThread  # noqa: E402
from preview_shaders.materialx_render import render_materialx  # noqa: E402
from preview_shaders.preview import sphere_cos_theta  # noqa: E402

BLENDER_PYTHON = ROOT / ".venv-blender" / "bin" / "python"
PREVIEW = ROOT / "fitting" / "exports" / "blender_preview.py"
CYCLES = ROOT / "docs" / "images" / "exports_cycles.png"
MATERIALX = ROOT / "docs" / "images" / "exports_materialx.png"
WHITE_SKY = ROOT / "docs" / "images" / "exports_white_sky.png"


def cycles(values, work: Path, size: int, samples: int) -> list[np.ndarray]:
    """Principled, Physical Conductor and imported glTF renders, (size, size, 3) uint8 each."""
    script, gltf = work / f"{values.name}.py", work / f"{values.name}.gltf"
    script.write_bytes(export_material(values, "blender", values.eta_i))
    gltf.write_bytes(export_material(values, "gltf", values.eta_i))
    images = []
    for source, extra in (
        (script, ["--output", "principled"]),
        (script, ["--output", "conductor"]),
        (gltf, ["--gltf"]),
    ):
        png = work / f"{values.name}-{len(images)}.png"
        subprocess.run(
            [
                str(BLENDER_PYTHON),
                str(PREVIEW),
                str(source),
                *extra,
                "--values",
                str(work / "values.json"),
                "--render",
                str(png),
                "--size",
                str(size),
                "--samples",
                str(samples),
            ],
            check=True,
            capture_output=True,
            timeout=600,
            cwd=work,
        )
        with Image.open(png) as image:
            images.append(np.asarray(image.convert("RGB")))
    return images


def white_sky(values, size: int) -> list[np.ndarray]:
    """Reference, mtlx, openpbr and gltf base Fresnel on the preview sphere, uint8."""
    mu, mask = sphere_cos_theta(size)
    # The curves are sampled at EXPORT_SAMPLES values of mu; per pixel, interpolate.
    curves = [values.target_ACEScg] + [
        lin_rec709_to_ACEScg(tool_curve(values, target)) for target in ("mtlx", "openpbr", "gltf")
    ]
    images = []
    for curve in curves:
        rgb = np.stack([np.interp(mu, values.cos_theta, curve[:, c]) for c in range(3)], axis=-1)
        rgb = np.where(mask[..., None], rgb, 0.18)
        images.append(to_uint8(ACEScg_to_sRGB(rgb)))
    return images


def materialx(values, size: int, thread: RenderThread) -> list[np.ndarray]:
    """Reference, then the mtlx and openpbr documents as MaterialX's GLSL renders them, uint8."""
    images = [white_sky(values, size)[0]]
    for format in ("mtlx", "openpbr"):
        rgb, coverage = render_materialx(export_material(values, format, values.eta_i).decode(), size, thread)
        centre = rgb[size // 2, size // 2]
        print(
            f"{values.name} {format}: centre pixel (cos theta 1), linear Rec.709 "
            f"{np.round(centre.astype(np.float64), 3).tolist()}; reference under the coat "
            f"{np.round(values.target[-1], 3).tolist()}"
        )
        rgb = np.where(coverage[..., None], lin_rec709_to_ACEScg(rgb), 0.18)
        images.append(to_uint8(ACEScg_to_sRGB(rgb)))
    return images


def grid(rows: list[list[np.ndarray]], gap: int = 2) -> Image.Image:
    h, w, _ = rows[0][0].shape
    out = np.full((len(rows) * (h + gap) - gap, len(rows[0]) * (w + gap) - gap, 3), 255, np.uint8)
    for i, row in enumerate(rows):
        for j, image in enumerate(row):
            out[i * (h + gap) : i * (h + gap) + h, j * (w + gap) : j * (w + gap) + w] = image
    return Image.fromarray(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/exports_renders.py")
    parser.add_argument("--materials", default="Au,Cu,Cr")
    parser.add_argument("--eta-i", type=float, default=1.5)
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--samples", type=int, default=16)
    args = parser.parse_args(argv)
    all_values = [export_values(library_material(m), args.eta_i) for m in args.materials.split(",")]
    grid([white_sky(v, max(args.size, 64)) for v in all_values]).save(WHITE_SKY)
    print(f"wrote {WHITE_SKY.relative_to(ROOT)}")
    with RenderThread("exports-materialx") as thread:
        grid([materialx(v, max(args.size, 64), thread) for v in all_values]).save(MATERIALX)
    print(f"wrote {MATERIALX.relative_to(ROOT)}")
    with tempfile.TemporaryDirectory() as work:
        rows = [cycles(v, Path(work), args.size, args.samples) for v in all_values]
    grid(rows).save(CYCLES)
    print(f"wrote {CYCLES.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
