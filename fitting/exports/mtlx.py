"""
MaterialX export
================

A MaterialX document whose ``surfacematerial`` is a coated metal built from
the standard ``pbrlib`` nodes: a ``dielectric_bsdf`` coat of ``ior`` eta_i
``layer``-ed over a ``conductor_bsdf`` whose ``ior`` and ``extinction`` are
per-channel values fitted so that MaterialX's layering (the coat's
reflection plus the conductor scaled by the coat's throughput, both at the
view angle in air) follows the physical coat on the metal seen from air
(:mod:`fitting.exports.seen_fit`). At eta_i 1 there is no coat: the
conductor alone, with the metal's own values in air. The node graph is the implementation of a node definition of its
own, ``ND_coated_metal_<name>``, whose inputs expose the roughness of the
metal and of the coat (perceptual, squared by ``roughness_anisotropy``) and
the coat index; the material instantiates it with the export's values.

-   :func:`mtlx_document`: the document as text.

References
----------
MaterialX Specification 1.39, Physically Based Shading Nodes
(``conductor_bsdf``, ``dielectric_bsdf``, ``layer``, ``roughness_anisotropy``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from ._xml import add_input, document, element_name, number, to_text, triple
from .seen_fit import seen_fidelity
from .values import ExportValues

__all__ = ["MODEL_KIND", "mtlx_document"]

MODEL_KIND = (
    "conductor_bsdf (exact Fresnel per channel) under MaterialX's layer with a dielectric_bsdf coat, "
    "ior / extinction fitted to the coated metal seen from air"
)


def mtlx_document(values: ExportValues) -> str:
    """
    The MaterialX document of ``values`` (one eta_i), UTF-8 text.

    The provenance (material, source, eta_i, model kind, generator) is an XML
    comment at the top and the ``doc`` string of the material.
    """
    ident = element_name(values.name)
    node = f"coated_metal_{ident}"
    nodedef_name = f"ND_{node}"
    provenance = values.provenance(MODEL_KIND, seen_fidelity(values, "mtlx"))
    root = document(provenance)
    fitted = values.tools["mtlx"]
    coat_on = fitted["coat"]

    nodedef = ET.SubElement(
        root, "nodedef", name=nodedef_name, node=node, nodegroup="pbr",
        doc=(f"{values.name} under a clear coat: conductor_bsdf, dielectric_bsdf coat" if coat_on
             else f"{values.name}: conductor_bsdf, no coat"),
    )
    add_input(nodedef, "base_roughness", "float", value=number(values.roughness),
              uimin="0.0", uimax="1.0", uiname="Metal Roughness")
    if coat_on:
        add_input(nodedef, "coat_roughness", "float", value=number(values.coat_roughness),
                  uimin="0.0", uimax="1.0", uiname="Coat Roughness")
        add_input(nodedef, "coat_ior", "float", value=number(values.eta_i), uiname="Coat IOR",
                  doc="The metal's values are fitted for this coat index; change it and re-export")
    ET.SubElement(nodedef, "output", name="out", type="surfaceshader")

    graph = ET.SubElement(root, "nodegraph", name=f"NG_{node}", nodedef=nodedef_name)
    base_alpha = ET.SubElement(graph, "roughness_anisotropy", name="base_alpha", type="vector2")
    add_input(base_alpha, "roughness", "float", interfacename="base_roughness")
    metal = ET.SubElement(graph, "conductor_bsdf", name="metal", type="BSDF")
    add_input(metal, "ior", "color3", value=triple(fitted["ior"]))
    add_input(metal, "extinction", "color3", value=triple(fitted["extinction"]))
    add_input(metal, "roughness", "vector2", nodename="base_alpha")
    if coat_on:
        coat_alpha = ET.SubElement(graph, "roughness_anisotropy", name="coat_alpha", type="vector2")
        add_input(coat_alpha, "roughness", "float", interfacename="coat_roughness")
        coat = ET.SubElement(graph, "dielectric_bsdf", name="coat", type="BSDF")
        add_input(coat, "ior", "float", interfacename="coat_ior")
        add_input(coat, "roughness", "vector2", nodename="coat_alpha")
        add_input(coat, "scatter_mode", "string", value="R")
        layered = ET.SubElement(graph, "layer", name="coated_metal", type="BSDF")
        add_input(layered, "top", "BSDF", nodename="coat")
        add_input(layered, "base", "BSDF", nodename="metal")
    surface = ET.SubElement(graph, "surface", name="shader", type="surfaceshader")
    add_input(surface, "bsdf", "BSDF", nodename="coated_metal" if coat_on else "metal")
    ET.SubElement(graph, "output", name="out", type="surfaceshader", nodename="shader")

    shader = ET.SubElement(root, node, name=f"{ident}_shader", type="surfaceshader")
    add_input(shader, "base_roughness", "float", value=number(values.roughness))
    if coat_on:
        add_input(shader, "coat_roughness", "float", value=number(values.coat_roughness))
        add_input(shader, "coat_ior", "float", value=number(values.eta_i))
    material = ET.SubElement(
        root, "surfacematerial", name=ident, type="material",
        doc="; ".join(f"{k}: {v}" for k, v in provenance.items()),
    )
    add_input(material, "surfaceshader", "surfaceshader", nodename=f"{ident}_shader")
    return to_text(root)
