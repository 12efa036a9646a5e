"""
``python -m fitting import FILE``
=================================

Reads a file back to the fit it was made from
(:func:`fitting.exports.readback.read_fit_file`): a binary pack, its JSON
view, a glTF or GLB, a MaterialX or OpenPBR document, or a Blender script of
this service, checked (checksum, version, values). Prints the fit as JSON:

    {"format": "mtlx", "fit_id": "<32 hex>", "fit_id_from": "file" | "content",
     "identity": {...}, "materials": [<pack JSON view of each material>]}

``fit_id`` is the file's own (an export's, or the pack JSON view's
``metrics.fit_id``) when it has one, else a new content address of the
materials' binary pack. ``-o PACK`` also writes the materials as a binary
pack. A damaged file exits with status 2 and a message naming what is wrong.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

__all__ = ["add_import_parser", "imported_fit"]


def imported_fit(data: bytes) -> tuple[dict, bytes]:
    """The JSON answer for a file's bytes, and the materials' binary pack."""
    from ..exports.readback import read_fit_file
    from ..models.pack import encode_pack, material_to_json

    read = read_fit_file(data)
    pack = encode_pack(read.materials)
    fit_ids = read.identity.get("fit_ids") or [read.identity.get("fit_id")]
    known = fit_ids[0] if len(read.materials) == 1 and fit_ids and fit_ids[0] else None
    answer = {
        "format": read.format,
        "fit_id": known or hashlib.sha256(pack).hexdigest()[:32],
        "fit_id_from": "file" if known else "content",
        "identity": read.identity,
        "materials": [material_to_json(m) for m in read.materials],
    }
    return answer, pack


def _cmd_import(args) -> int:
    path = Path(args.file)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise ValueError(f"`FILE` cannot be read: {error.strerror}: {args.file}") from None
    answer, pack = imported_fit(data)
    if args.output:
        Path(args.output).write_bytes(pack)
        print(f"wrote {args.output}", file=sys.stderr)
    print(json.dumps(answer, indent=2))
    return 0


def add_import_parser(sub) -> None:
    p = sub.add_parser("import", help="read a pack or an export of this service back to its fit")
    p.add_argument("file", metavar="FILE", help=".cfpk, .json, .gltf, .glb, .mtlx, .openpbr.mtlx or .py")
    p.add_argument("-o", "--output", metavar="PACK", help="also write the fit as a binary pack")
    p.set_defaults(func=_cmd_import)
