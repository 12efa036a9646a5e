"""
Command line
============

``python -m fitting library | fit | reproduce | scene | ibl | ibl-lut``

-   ``library [QUERY]``: the conductor catalogue (every opaque page a batch fits, by name).
-   ``fit gold`` (any catalogue name, symbol or id), ``fit --nk FILE`` or ``fit --page main/Ag/Johnson``: fit and write a binary pack (``-o``) or
    print its JSON view (``--json``); ``--eta-range 1:2.5`` sets the domain, ``--model`` the kind
    (``coated-conductor``, the default, or ``rgb-conductor``); ``--snippet glsl`` / ``hlsl`` writes the
    fit as a ready-to-paste shader snippet, ``--export FORMAT`` an export for one coating index.
-   ``reproduce``: the paper's Table 1 for all 22 conductors and the Section
    4.3 float16 study, printed and written to ``-o FILE`` (default a temporary
    file; ``--write-docs``: ``docs/results.md``).
-   ``scene FILE``: a pack with only what a scene needs (:mod:`fitting.cli.scene`).
-   ``batch --shelf main``: a selection of the refractiveindex.info database
    into one pack and report (:mod:`fitting.cli.batch`); ``catalogue``: rebuild
    the conductor catalogue from the shelf.
-   ``ibl MATERIAL``, ``ibl-lut -o FILE``: split-sum pre-integration against
    Monte Carlo, and the LUT (:mod:`fitting.cli.ibl`).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

from ..domain import DEFAULT_ETA_I_RANGE, DEFAULT_WORKING_SPACE, WORKING_SPACES

__all__ = ["COMMANDS", "LazyChoices", "build_parser", "main", "parse_eta_range"]


def parse_eta_range(text: str) -> tuple[float, float]:
    """``"1:2.5"`` -> (1.0, 2.5); a single number gives a single eta_i."""
    parts = text.split(":")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--eta-range must be LO:HI, got {text!r}") from None
    if len(values) == 1:
        values = values * 2
    if len(values) != 2:
        raise argparse.ArgumentTypeError(f"--eta-range must be LO:HI, got {text!r}")
    return values[0], values[1]


def _cmd_library(args) -> int:
    from ..optics.catalogue import search_catalogue

    for entry in search_catalogue(args.query):
        lo, hi = entry["wavelength_range_nm"]
        print(
            f"{entry['id']:28s} {entry['name']:30s} {entry['symbol']:10s} {entry['category']:15s} "
            f"{lo:7.1f}-{hi:8.1f} nm  {entry['label']}"
        )
    return 0


def _cmd_fit(args) -> int:
    from ..fits.kinds import fit_model
    from ..models.pack import encode_pack, material_to_json
    from .materials import material_nk

    nk = material_nk(args)
    if nk is None:
        return 2
    if args.export is not None:
        return _write_export(nk, args)
    extra = {} if args.max_gap_nm is None else {"max_gap_nm": args.max_gap_nm}
    # The metrics as the service stores them (its float32 reference, within 0.001 Delta E of float64).
    evaluate = False if args.no_metrics else "float32"
    result = fit_model(nk, args.eta_range, args.model, objective=args.objective, evaluate=evaluate, **extra)
    for warning in result.quality.get("warnings", []):
        # Sparse data, outliers or a model outside [0, 1] are said, and refused with --strict.
        if args.strict:
            print(f"error: the fit of {nk.name!r}: {warning}; nothing written (--strict)", file=sys.stderr)
            return 3
        print(f"warning: {warning}", file=sys.stderr)
    if not result.success:
        what = (
            f"the fit of {nk.name!r} did not converge (solver status {result.status}: "
            f"{result.message}); its coefficients are the best found"
        )
        if args.strict:
            print(f"error: {what}; nothing written (--strict)", file=sys.stderr)
            return 3
        print(f"warning: {what}", file=sys.stderr)
    if args.snippet is not None:
        return _write_snippet(nk, result, args)
    view = material_to_json(result.packed)
    view["fit"] = result.summary()
    try:
        text = json.dumps(view, indent=2, allow_nan=False)
    except ValueError:
        print(
            f"error: the fit of {nk.name!r} gave non-finite figures: the data cannot be fitted; nothing written",
            file=sys.stderr,
        )
        return 3
    if args.output:
        Path(args.output).write_bytes(encode_pack([result.packed]))
        print(f"wrote {args.output}", file=sys.stderr)
    if args.json or not args.output:
        print(text)
    return 0


def _write_export(nk, args) -> int:
    from ..exports import export_material
    from ..fits.kinds import fit_model

    # The fit's own float16 model travels in the glTF export's extension.
    model = fit_model(nk, args.eta_range, args.model, objective=args.objective, evaluate=False).packed
    body = export_material(
        nk, args.export, args.eta_i, args.roughness, args.coat_roughness, model, working_space=args.working_space
    )
    if args.output:
        Path(args.output).write_bytes(body)
        print(f"wrote {args.output}", file=sys.stderr)
    else:
        sys.stdout.flush()
        sys.stdout.buffer.write(body)
        sys.stdout.flush()
    return 0


def _write_snippet(nk, result, args) -> int:
    from ..exports.snippets import SnippetMaterial, snippet
    from ..fits.metrics import headline

    material = SnippetMaterial(nk.name, nk.source, "python -m fitting fit", headline(result.metrics), result.packed)
    text = snippet(args.snippet, [material], nk.name, "python -m fitting fit")
    if args.output:
        Path(args.output).write_text(text, encoding="utf-8")
        print(f"wrote {args.output}", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


class LazyChoices(Sequence[str]):
    """
    The choices of an option read from a registry when argparse first asks
    (a check of a value, a help or an error), not when the parser is built:
    a command that never reads them never imports the registry's writers
    (the export formats' are most of the CLI's start otherwise). A plugin
    registered before the parse is among them.
    """

    def __init__(self, names: Callable[[], Iterable[str]]):
        self._names = names

    def _all(self) -> tuple[str, ...]:
        return tuple(self._names())

    def __contains__(self, value: object) -> bool:
        return value in self._all()

    def __iter__(self) -> Iterator[str]:
        return iter(self._all())

    def __len__(self) -> int:
        return len(self._all())

    def __getitem__(self, index):  # type: ignore[override]
        return self._all()[index]


def _export_formats() -> tuple[str, ...]:
    from ..exports.formats import EXPORT_FORMATS

    return tuple(EXPORT_FORMATS)


def _add_library(sub) -> None:
    p = sub.add_parser("library", help="list the library's conductors (or those matching QUERY)")
    p.add_argument("query", nargs="?", help="words of a name or symbol, e.g. 'stainless' or TiN")
    p.set_defaults(func=_cmd_library)


def _add_fit(sub) -> None:
    from ..fits.settings import DEFAULT_OBJECTIVE, OBJECTIVES
    from ..models.kinds import DEFAULT_MODEL, MODEL_KINDS

    p = sub.add_parser("fit", help="fit a library material or an n, k file")
    p.add_argument(
        "material", nargs="?", help="a library conductor by name, symbol or id, any case: gold, Au, Ti.Johnson"
    )
    p.add_argument("--nk", metavar="FILE", help="n, k file: CSV, JSON or refractiveindex.info YAML")
    p.add_argument("--page", metavar="SHELF/BOOK/PAGE", help="any refractiveindex.info page, e.g. main/SiO2/Malitson")
    p.add_argument("--name", help="material name for --nk or --page")
    p.add_argument(
        "--eta-range",
        type=parse_eta_range,
        default=DEFAULT_ETA_I_RANGE,
        metavar="LO:HI",
        help="eta_i domain of the fit (default 1:2.5)",
    )
    p.add_argument("--objective", choices=OBJECTIVES, default=DEFAULT_OBJECTIVE)
    p.add_argument("--model", choices=MODEL_KINDS, default=DEFAULT_MODEL, help="model kind (default %(default)s)")
    p.add_argument("-o", "--output", metavar="FILE", help="write the binary pack here")
    p.add_argument("--json", action="store_true", help="print the JSON view")
    p.add_argument("--no-metrics", action="store_true", help="skip the 100x100 metrics")
    p.add_argument(
        "--export",
        choices=LazyChoices(_export_formats),
        metavar="FORMAT",  # argparse lists the choices in the metavar when adding the option: not here, lazily
        help="write this export (%(choices)s; docs/exports.md) to -o or stdout instead of a pack",
    )
    p.add_argument(
        "--snippet",
        choices=("glsl", "hlsl"),
        help="write a ready-to-paste GLSL or HLSL snippet of the fit to -o or stdout instead of a pack",
    )
    p.add_argument("--eta-i", type=float, default=1.5, help="coating index of --export, [1, 3] (default 1.5)")
    p.add_argument("--roughness", type=float, default=0.2, help="metal roughness of --export, [0, 1]")
    p.add_argument("--coat-roughness", type=float, default=0.03, help="coat roughness of --export, [0, 1]")
    p.add_argument(
        "--working-space",
        choices=WORKING_SPACES,
        default=DEFAULT_WORKING_SPACE,
        help="working space --export is fitted and written in (default %(default)s)",
    )
    p.add_argument(
        "--strict",
        action="store_true",
        help="exit with status 3 (writing nothing) on any warning: the fit does not "
        "converge, its model is not proven inside [0, 1], or the data are sparse, "
        "gapped or hold an outlier",
    )
    p.add_argument(
        "--max-gap-nm",
        type=float,
        default=None,
        metavar="NM",
        help="largest gap between samples inside 360-830 nm accepted (default 120; "
        "larger fits sparse data with a warning in the result and the pack)",
    )
    p.set_defaults(func=_cmd_fit)


def _add_reproduce(sub) -> None:
    p = sub.add_parser(
        "reproduce", help="print Table 1 and write the results page (Table 1, Section 4.3, the worst point)"
    )
    where = p.add_mutually_exclusive_group()
    where.add_argument("-o", "--output", metavar="FILE", help="write the page here (default: a new temporary file)")
    where.add_argument("--write-docs", action="store_true", help="update docs/results.md")
    p.add_argument("--materials", help="comma-separated subset (default: all 22)")
    p.set_defaults(func=lambda args: __import__("fitting.cli.reproduce", fromlist=["run"]).run(args))


def _add_scene(sub) -> None:
    from .scene import add_scene_parser

    add_scene_parser(sub)


def _add_batch(sub) -> None:
    from .batch import add_batch_parser

    add_batch_parser(sub, parse_eta_range)


def _add_catalogue(sub) -> None:
    from .batch import add_catalogue_parser

    add_catalogue_parser(sub)


def _add_ibl(sub) -> None:
    from .ibl import add_ibl_parsers

    add_ibl_parsers(sub)


def _add_import(sub) -> None:
    from .import_fit import add_import_parser

    add_import_parser(sub)


COMMANDS: dict[str, Callable[[Any], None]] = {
    "library": _add_library,
    "fit": _add_fit,
    "reproduce": _add_reproduce,
    "scene": _add_scene,
    "batch": _add_batch,
    "catalogue": _add_catalogue,
    "ibl": _add_ibl,
    "ibl-lut": _add_ibl,
    "import": _add_import,
}
"""Each sub-command by name, and what adds its parser (``ibl`` adds ``ibl-lut`` too)."""


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """
    The command line's parser: every sub-command, or with ``command`` (one
    of :data:`COMMANDS`) that one alone, so that a command imports only what
    its own options need (``fit Au`` neither the batch's, the scene's nor
    the exports' modules).
    """
    parser = argparse.ArgumentParser(
        prog="python -m fitting",
        description="Measured n, k of a conductor to the float16 coated-conductor Fresnel model.",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    adders = [COMMANDS[command]] if command in COMMANDS else list(dict.fromkeys(COMMANDS.values()))
    for add in adders:
        add(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    from .plugins import load_plugins

    try:
        load_plugins()  # before the parser: a plugin's formats and kinds are among its choices
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    argv = sys.argv[1:] if argv is None else list(argv)
    # The first word is the sub-command (the main parser has no option but --help): only its parser is built.
    parser = build_parser(argv[0] if argv else None)
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
