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


def document(provenance: dict) -> ET.Element:
    root = ET.Element("materialx", version=MATERIALX_VERSION, colorspace="lin_rec709")
    root.append(ET.Comment(comment_text(provenance)))
    return root


def add_input(parent: ET.Element, name: str, type_: str, **attributes: str) -> ET.Element:
    return ET.SubElement(parent, "input", name=name, type=type_, **attributes)


def to_text(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
