"""
OpenPBR export
==============

A MaterialX document with one ``open_pbr_surface`` (OpenPBR Surface 1.1 as
shipped in MaterialX's ``bxdf`` library): a fully metallic base whose
``base_color`` and ``specular_color`` are the F0 and F82 tint fitted so that
OpenPBR's coat (``coat_weight`` 1, ``coat_ior`` eta_i, ``coat_darkening`` 1,
the specification's default: the base darkened by the coat's internal
reflections) over that metal, as MaterialX builds it, follows the physical
coat on the metal seen from air (:mod:`fitting.exports.seen_fit`). At eta_i 1
there is no coat (``coat_weight`` 0). ``specular_roughness`` and
``coat_roughness`` are the surface's own inputs. The shader is
``<name>_<id>_<eta>_openpbr_shader`` and the material
``<name>_<id>_<eta>_openpbr`` (:func:`fitting.exports.naming.element_stem`):
unique per fit and coat index, and apart from the MaterialX export's, so
both merge into one document. The document's ``colorspace`` is the
export's working space; the document and the material carry the fit's
identity as the MaterialX export does.

-   :func:`openpbr_document`: the document as text.

References
----------
Andersson, A. et al. (2024). OpenPBR Surface Specification, metal and coat.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from ._xml import add_input, document, identity_attributes, number, to_text, triple
from .naming import element_stem, identity
from .seen_fit import seen_fidelity
from .values import ExportValues

__all__ = ["MODEL_KIND", "openpbr_document"]

MODEL_KIND = "f82-tint metal under OpenPBR's coat: F0 and F82 tint fitted to the coated metal seen from air"


def openpbr_document(values: ExportValues) -> str:
    """The OpenPBR (MaterialX) document of ``values``, UTF-8 text."""
    ident = f"{element_stem(values)}_openpbr"
    provenance = values.provenance(MODEL_KIND, seen_fidelity(values, "openpbr"))
    root = document(provenance, identity(values, with_pack=True))
    fitted = values.tools["openpbr"]
    coat_on = fitted["coat"]
    shader = ET.SubElement(root, "open_pbr_surface", name=f"{ident}_shader", type="surfaceshader")
    for name, type_, value in (
        ("base_weight", "float", number(1.0)),
        ("base_color", "color3", triple(fitted["base_color"])),
        ("base_metalness", "float", number(1.0)),
        ("specular_weight", "float", number(1.0)),
        ("specular_color", "color3", triple(fitted["specular_color"])),
        ("specular_roughness", "float", number(values.roughness)),
        ("coat_weight", "float", number(1.0 if coat_on else 0.0)),
        ("coat_color", "color3", triple((1.0, 1.0, 1.0))),
        ("coat_roughness", "float", number(values.coat_roughness)),
        ("coat_ior", "float", number(values.eta_i)),
        # The default, written out: the fit is made with it on (the physical
        # bounces between coat and metal darken and tint the metal too).
        ("coat_darkening", "float", number(fitted.get("coat_darkening", 1.0))),
    ):
        add_input(shader, name, type_, value=value)
    material = ET.SubElement(
        root,
        "surfacematerial",
        name=ident,
        type="material",
        doc="; ".join(f"{k}: {v}" for k, v in provenance.items()),
        **identity_attributes(identity(values, with_pack=True)),
    )
    add_input(material, "surfaceshader", "surfaceshader", nodename=f"{ident}_shader")
    return to_text(root)
