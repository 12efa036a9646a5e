"""
``python -m fitting scene FILE [-o PACK] [--json]``
===================================================

Fits a scene description (:mod:`fitting.fits.scene_schema`,
:func:`fitting.fits.scene_fit.fit_scene`), prints its table or JSON report
and writes the pack to a new file, never replacing one.

-   :func:`add_scene_parser`: registers the sub-command.
-   :func:`scene_command`: runs it.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

from ..fits.scene_fit import fit_scene
from ..fits.scene_schema import parse_scene

__all__ = ["add_scene_parser", "scene_command"]


def _format_table(report: dict[str, Any]) -> str:
    rows = [
        f"scene {report['scene']}",
        f"{'name':<16} {'eta_i':<18} {'deg':>3} {'bytes':>6} {'general':>7} "
        f"{'dE mean':>8} {'general':>8} {'dE max':>7} {'general':>8}",
    ]
    for m in report["materials"]:
        eta = json.dumps(m["eta_i"])
        rows.append(
            f"{m['name'][:16]:<16} {eta[:18]:<18} {m['degree']:>3} {m['bytes']:>6} "
            f"{m['general']['bytes']:>7} {m['delta_E_2000']['mean']:>8.3f} "
            f"{m['general']['delta_E_2000']['mean']:>8.3f} {m['delta_E_2000']['max']:>7.3f} "
            f"{m['general']['delta_E_2000']['max']:>8.3f}"
        )
    for m in report["materials"]:
        if "choice" in m:
            rows.append(f"{m['name']}: {m['model']}: {m['choice']['reason']}")
    totals = report["totals"]
    rows.append(
        f"pack {totals['pack_bytes']} bytes (general {totals['general_pack_bytes']}), "
        f"{totals['coefficients']} coefficients (general {totals['general_coefficients']}), "
        f"mean Delta E 2000 {totals['delta_E_2000_mean']:.3f} "
        f"(general {totals['general_delta_E_2000_mean']:.3f})"
    )
    return "\n".join(rows)


def _write_new_file(path: Path, data: bytes) -> None:
    """Write ``data`` to a new file ``path`` atomically; never replace one."""
    directory = path.parent if str(path.parent) else Path(".")
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=directory)
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
        # link() fails if the target exists: a file the user saved is never replaced.
        os.link(temporary, path)
    finally:
        os.unlink(temporary)


def scene_command(args: argparse.Namespace) -> int:
    """
    ``python -m fitting scene FILE [-o PACK] [--json]``: fit a scene, print
    the table (or the JSON report) and write the pack (``.json`` suffix: the
    JSON view, otherwise binary). Returns the exit status: 0, or 2 with a
    message on stderr for bad input or an existing output file.
    """
    try:
        output = Path(args.output) if args.output else None
        if output is not None and output.exists():
            raise ValueError(f"`--output` {output} exists; it is never overwritten, choose a new name")
        try:
            text = Path(args.file).read_bytes()
        except OSError as error:
            raise ValueError(f"cannot read scene `FILE` {args.file}: {error.strerror}") from None
        result = fit_scene(parse_scene(text))
        report = result.report()
        if output is not None:
            data = result.pack_json().encode() if output.suffix == ".json" else result.pack_bytes()
            try:
                _write_new_file(output, data)
            except FileExistsError:
                raise ValueError(f"`--output` {output} exists; it is never overwritten") from None
            except OSError as error:
                raise ValueError(f"cannot write `--output` {output}: {error.strerror}") from None
            report["output"] = str(output)
    except ValueError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(json.dumps(report, indent=2) if args.json else _format_table(report))
    return 0


def add_scene_parser(subparsers) -> argparse.ArgumentParser:
    """Register the ``scene`` subcommand on an ``argparse`` subparsers object."""
    parser = subparsers.add_parser(
        "scene",
        help="fit only the materials and coating indices a scene uses",
        description=(
            "Fit each material of a scene description over the eta_i the scene "
            "uses, with the lowest polynomial degree that serves it, and report "
            "bytes and Delta E 2000 against the general 27-coefficient fit."
        ),
    )
    parser.add_argument("file", metavar="FILE", help="scene description (JSON)")
    parser.add_argument(
        "-o",
        "--output",
        metavar="PACK",
        help="write the scene pack here (.json: JSON view, else binary); never overwrites",
    )
    parser.add_argument("--json", action="store_true", help="print the JSON report")
    parser.set_defaults(func=scene_command)
    return parser
