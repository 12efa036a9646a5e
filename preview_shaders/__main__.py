"""
Command line: ``python -m preview_shaders render ...``.

    python -m preview_shaders render --material Au --eta-i 1.5 --size 512 \\
        --compare lazanyi -o out.png
    python -m preview_shaders render --fit pack.cfpk --eta-i 2.0 -o out.png
    python -m preview_shaders render --material Cr --eta-i 1.5 --roughness 0.3 \
        --mode coated --coat-roughness 0.1 --environment studio -o rough.png

Without ``--fit`` the built-in material is fitted on the spot
(:func:`fitting.fits.material.fit_material`); with it, the material is read from a
binary or JSON pack (``--material`` picks one by name, else the first). The
comparisons need n, k: those of the built-in material of that name.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from fitting.models.pack import PACK_MAGIC, decode_pack, pack_from_json
from fitting.optics.library import LIBRARY_NAMES, library_material

from .display import encode_png, false_colour
from .preview import COMPARISONS, ENVIRONMENTS, MODES, PreviewRenderer


def _read_pack(path: Path, name: str | None):
    data = path.read_bytes()
    materials = decode_pack(data) if data[:4] == PACK_MAGIC else pack_from_json(data)
    if name is None:
        return materials[0]
    for material in materials:
        if material.name == name:
            return material
    names = ", ".join(m.name for m in materials)
    raise ValueError(f"`--material` {name!r} is not in {path} (it holds {names})")


def _render(args) -> int:
    if args.fit is None:
        if args.material is None:
            raise ValueError("`--material` or `--fit` is required")
        if args.material not in LIBRARY_NAMES:
            raise ValueError(f"`--material` must be one of {', '.join(LIBRARY_NAMES)}, got {args.material!r}")
        from fitting.fits.material import fit_material

        nk = library_material(args.material)
        packed = fit_material(nk).packed
    else:
        packed = _read_pack(args.fit, args.material)
        nk = library_material(packed.name) if packed.name in LIBRARY_NAMES else None
    with PreviewRenderer() as renderer:
        result = renderer.render_preview(
            packed,
            nk,
            args.eta_i,
            args.size,
            args.compare,
            args.environment,
            roughness=args.roughness,
            mode=args.mode,
            coat_roughness=args.coat_roughness,
        )
    args.output.write_bytes(result.png)
    print(
        f"wrote {args.output} ({packed.name}, eta_i {args.eta_i:g}, {args.size} px, "
        f"compare {args.compare}, {args.environment}, {args.mode}, roughness {args.roughness:g}"
        + (f", coat roughness {args.coat_roughness:g}" if args.mode == "coated" else "")
        + ")"
    )
    if result.delta_E is not None:
        print(f"mean Delta E 2000 over the sphere: {result.delta_E_mean:.4f}")
        print(f"mean FLIP over the sphere: {result.flip_mean:.4f}")
        if args.delta_e_map:
            args.delta_e_map.write_bytes(encode_png(false_colour(result.delta_E, 2.0, "viridis")))
        if args.flip_map:
            args.flip_map.write_bytes(encode_png(false_colour(result.flip, 1.0, "magma")))
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m preview_shaders")
    commands = parser.add_subparsers(dest="command", required=True)
    render = commands.add_parser("render", help="render the preview sphere to a PNG")
    render.add_argument("--material", help="built-in conductor (fitted on the spot), or the material's name in --fit")
    render.add_argument("--fit", type=Path, help="a coefficient pack, binary or JSON")
    render.add_argument("--eta-i", type=float, default=1.5, help="coating index, [1, 3]")
    render.add_argument("--size", type=int, default=512, help="pixels per side, 64..2048")
    render.add_argument("--compare", default="none", help=" | ".join(COMPARISONS))
    render.add_argument("--environment", default="white_sky", help=" | ".join(ENVIRONMENTS))
    render.add_argument(
        "--roughness", type=float, default=0.0, help="GGX perceptual roughness, [0, 1] (0: the smooth sphere)"
    )
    render.add_argument("--mode", default="immersed", help=" | ".join(MODES))
    render.add_argument(
        "--coat-roughness", type=float, default=0.0, help="with --mode coated: the coat's roughness, [0, 1]"
    )
    render.add_argument(
        "--delta-e-map", type=Path, help="with --compare reference: Delta E 2000 map PNG (viridis, 0..2)"
    )
    render.add_argument("--flip-map", type=Path, help="with --compare reference: FLIP map PNG (magma, 0..1)")
    render.add_argument("-o", "--output", type=Path, required=True)
    args = parser.parse_args(argv)
    try:
        return _render(args)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
