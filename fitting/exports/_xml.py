"""Shared helpers of the MaterialX writers: numbers, names and the document shell."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

MATERIALX_VERSION = "1.39"
"""The MaterialX version the documents declare (the ``materialx`` package's)."""


def number(value: float) -> str:
    """A float with 6 significant digits, as MaterialX values are written."""
    return f"{float(value):.6g}"


def triple(values) -> str:
    return ", ".join(number(v) for v in values)


def element_name(text: str) -> str:
    """``text`` as a MaterialX element name: letters, digits, underscores, no leading digit."""
    name = re.sub(r"_+", "_", re.sub(r"[^A-Za-z0-9_]", "_", text)).strip("_") or "material"
    return name if not name[0].isdigit() else "M_" + name


def comment_text(provenance: dict) -> str:
    """Provenance as comment text: no ``--`` (not allowed inside an XML comment)."""
    lines = [f"{key}: {value}" for key, value in provenance.items()]
    return (" " + "\n     ".join(lines) + " ").replace("--", "- -")


IDENTITY_ATTRIBUTES = {
    "fit_id": "coatedfresnel_fit_id",
    "fit_id_kind": "coatedfresnel_fit_id_kind",
    "service_version": "coatedfresnel_version",
    "eta_i": "coatedfresnel_eta_i",
    "working_space": "coatedfresnel_working_space",
    "pack": "coatedfresnel_pack",
}
"""Identity field (:func:`fitting.exports.naming.identity`) -> the MaterialX attribute that carries it
on the document and on the material (which keeps it when documents are merged)."""


def identity_attributes(identity: dict) -> dict:
    """``identity`` as MaterialX attributes (:data:`IDENTITY_ATTRIBUTES`), all text; ``None`` left out."""
    return {IDENTITY_ATTRIBUTES[key]: str(value) for key, value in identity.items() if value is not None}


def document(provenance: dict, identity: dict) -> ET.Element:
    """
    The ``materialx`` element: its ``colorspace`` the export's working space
    (every colour in it is in that space) and the identity attributes.
    """
    root = ET.Element(
        "materialx", version=MATERIALX_VERSION, colorspace=identity["working_space"], **identity_attributes(identity)
    )
    root.append(ET.Comment(comment_text(provenance)))
    return root


def add_input(parent: ET.Element, name: str, type_: str, **attributes: str) -> ET.Element:
    return ET.SubElement(parent, "input", name=name, type=type_, **attributes)


def to_text(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
