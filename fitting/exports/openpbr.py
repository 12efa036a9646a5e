"""
OpenPBR export
==============

A MaterialX document with one ``open_pbr_surface`` (OpenPBR Surface 1.1 as
shipped in MaterialX's ``bxdf`` library): a fully metallic base whose
``base_color`` and ``specular_color`` are the F0 and F82 tint of the F82-tint
model fitted to the metal's reflectance *under* the coat
(:mod:`fitting.exports.values`), with ``coat_weight`` 1 and ``coat_ior``
eta_i, ``coat_darkening`` 0. OpenPBR leaves the Fresnel of a metal under a coat undefined (the
F82 model assumes air), so the fit to the curve under the coat is what lets
it see the coat; ``specular_roughness`` and ``coat_roughness`` are the
surface's own inputs.

-   :func:`openpbr_document`: the document as text.

References
----------
Andersson, A. et al. (2024). OpenPBR Surface Specification, metal and coat.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from ._xml import add_input, document, element_name, number, to_text, triple
from .tool_fresnel import export_fidelity
from .values import ExportValues

__all__ = ["MODEL_KIND", "openpbr_document"]

MODEL_KIND = "f82-tint: F0 and F82 tint fitted to the reflectance under the coat"


def openpbr_document(values: ExportValues) -> str:
    """The OpenPBR (MaterialX) document of ``values``, UTF-8 text."""
    ident = element_name(values.name)
    provenance = values.provenance(MODEL_KIND, export_fidelity(values, "openpbr"))
    root = document(provenance)
    shader = ET.SubElement(root, "open_pbr_surface", name=f"{ident}_openpbr", type="surfaceshader")
    for name, type_, value in (
        ("base_weight", "float", number(1.0)),
        ("base_color", "color3", triple(values.F0)),
        ("base_metalness", "float", number(1.0)),
        ("specular_weight", "float", number(1.0)),
        ("specular_color", "color3", triple(values.F82_tint)),
        ("specular_roughness", "float", number(values.roughness)),
        ("coat_weight", "float", number(1.0)),
        ("coat_color", "color3", triple((1.0, 1.0, 1.0))),
        ("coat_roughness", "float", number(values.coat_roughness)),
        ("coat_ior", "float", number(values.eta_i)),
        # Off: the fitted F0 and tint already are the metal seen under the
        # coat; OpenPBR's darkening (internal reflections in the coat, meant
        # for rough or diffuse bases) would darken it a second time.
        ("coat_darkening", "float", number(0.0)),
    ):
        add_input(shader, name, type_, value=value)
    material = ET.SubElement(
        root, "surfacematerial", name=ident, type="material",
        doc="; ".join(f"{k}: {v}" for k, v in provenance.items()),
    )
    add_input(material, "surfaceshader", "surfaceshader", nodename=f"{ident}_openpbr")
    return to_text(root)
