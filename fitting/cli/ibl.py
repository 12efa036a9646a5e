"""
``python -m fitting ibl`` and ``python -m fitting ibl-lut``
===========================================================

-   ``ibl MATERIAL --eta-i E --roughness R [--mode immersed|coated] --json``:
    the specular directional albedo of the material's default fit at a set
    of NdotV, three ways: the split-sum LUT (:mod:`fitting.shading.ibl`),
    Monte Carlo with the model's Fresnel and Monte Carlo with the exact
    spectral Fresnel of the measured n, k (:mod:`fitting.shading.monte_carlo`).
    ``MATERIAL`` takes what ``fit`` takes (a library name, ``--nk FILE``,
    ``--page SHELF/BOOK/PAGE``). Prints
    ``{"n_dot_v": [...], "split_sum": [[R, G, B], ...], "monte_carlo": [...],
    "monte_carlo_stderr": [...], "reference": [...]}`` (linear ACEScg); without
    ``--json``, a table.
-   ``ibl-lut -o FILE``: writes the default LUT (format in docs/shading.md).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from ..domain import check_eta_i

__all__ = ["add_ibl_parsers", "DEFAULT_N_DOT_V"]

DEFAULT_N_DOT_V = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)


def _unit_interval(name: str):
    def parse(text: str) -> float:
        import argparse

        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number, got {text!r}") from None
        if not 0.0 <= value <= 1.0:
            raise argparse.ArgumentTypeError(f"{name} must lie in [0, 1], got {text}")
        return value

    return parse


def _n_dot_v(text: str) -> tuple[float, ...]:
    import argparse

    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--n-dot-v must be numbers like 0.1,0.5, got {text!r}") from None
    if not values or not all(0.0 < v <= 1.0 for v in values):
        raise argparse.ArgumentTypeError(f"--n-dot-v values must lie in (0, 1], got {text!r}")
    return values


def _cmd_ibl(args) -> int:
    from ..fits.material import fit_material
    from ..models.coated_conductor import collapse_to_eta_i
    from ..shading.ibl import split_sum_coated, split_sum_model
    from ..shading.microfacet import model_fresnel
    from ..shading.monte_carlo import directional_albedo, spectral_fresnel
    from .materials import material_nk

    eta_i = check_eta_i(args.eta_i)
    nk = material_nk(args)
    if nk is None:
        return 2
    packed = fit_material(nk).packed
    F0, a, alpha = collapse_to_eta_i(packed.coefficients.astype(np.float64), eta_i, packed.eta_i_range)[..., 0]
    mu = np.array(args.n_dot_v)
    if args.mode == "coated":
        split = split_sum_coated(mu, args.roughness, F0, a, alpha, eta_i, args.coat_roughness)
    else:
        split = split_sum_model(mu, args.roughness, F0, a, alpha)
    common = dict(mode=args.mode, eta_i=eta_i, coat_roughness=args.coat_roughness, samples=args.samples, seed=args.seed)
    mc = directional_albedo(mu, args.roughness, model_fresnel(F0, a, alpha), **common)
    reference = directional_albedo(mu, args.roughness, spectral_fresnel(nk, eta_i), **common)
    view = {
        "n_dot_v": mu.tolist(),
        "split_sum": split.tolist(),
        "monte_carlo": mc.mean.tolist(),
        "monte_carlo_stderr": mc.stderr.tolist(),
        "reference": reference.mean.tolist(),
    }
    if args.json:
        print(json.dumps(view))
        return 0
    print(
        f"{packed.name}, {args.mode}, eta_i {eta_i:g}, roughness {args.roughness:g}, "
        f"{args.samples} MC samples per NdotV (linear ACEScg)"
    )
    print("NdotV  split sum (R G B)        MC model (R G B)         stderr    MC spectral reference")
    for i, m in enumerate(mu):
        fmt = lambda v: " ".join(f"{x:.4f}" for x in v)  # noqa: E731
        print(f"{m:5.2f}  {fmt(split[i])}  {fmt(mc.mean[i])}  {mc.stderr[i].max():.1e}  {fmt(reference.mean[i])}")
    return 0


def _cmd_ibl_lut(args) -> int:
    from ..shading.ibl import default_lut, encode_lut

    blob = encode_lut(default_lut())
    Path(args.output).write_bytes(blob)
    print(f"wrote {args.output} ({len(blob)} bytes)", file=sys.stderr)
    return 0


def add_ibl_parsers(sub) -> None:
    """Register ``ibl`` and ``ibl-lut`` on the sub-command parsers ``sub``."""
    from ..shading.microfacet import MODES
    from ..shading.monte_carlo import MC_SAMPLES

    p = sub.add_parser("ibl", help="split-sum vs Monte Carlo directional albedo of a material")
    p.add_argument("material", nargs="?", help="library material name, e.g. Cr")
    p.add_argument("--nk", metavar="FILE", help="n, k file: CSV, JSON or refractiveindex.info YAML")
    p.add_argument("--page", metavar="SHELF/BOOK/PAGE", help="any refractiveindex.info page")
    p.add_argument("--name", help="material name for --nk or --page")
    p.add_argument("--eta-i", type=float, default=1.0, help="index of the medium or coat (default 1)")
    p.add_argument(
        "--roughness",
        type=_unit_interval("--roughness"),
        default=0.5,
        help="perceptual roughness of the metal, [0, 1] (default 0.5)",
    )
    p.add_argument("--mode", choices=MODES, default="immersed")
    p.add_argument(
        "--coat-roughness",
        type=_unit_interval("--coat-roughness"),
        default=0.0,
        help="perceptual roughness of the coat (coated mode; default 0)",
    )
    p.add_argument(
        "--n-dot-v",
        type=_n_dot_v,
        default=DEFAULT_N_DOT_V,
        metavar="LIST",
        help="comma-separated NdotV in (0, 1] (default 0.05,0.1,0.2,...,1)",
    )
    p.add_argument("--samples", type=int, default=MC_SAMPLES, help=f"MC draws per NdotV (default {MC_SAMPLES})")
    p.add_argument("--seed", type=int, default=0, help="seed of the Monte Carlo (default 0)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=_cmd_ibl)

    p = sub.add_parser("ibl-lut", help="write the split-sum LUT (docs/shading.md)")
    p.add_argument("-o", "--output", required=True, metavar="FILE")
    p.set_defaults(func=_cmd_ibl_lut)
