"""
MaterialX export
================

A MaterialX document whose ``surfacematerial`` is a coated metal built from
the standard ``pbrlib`` nodes: a ``dielectric_bsdf`` coat of ``ior`` eta_i
``layer``-ed over a ``conductor_bsdf`` whose ``ior`` and ``extinction`` are
per-channel values (each channel's n and k affine in the facing 1 - cos theta,
from a graph of ``normal`` and ``viewdirection``, where the fit found
that better than constants) fitted so that MaterialX's layering (the coat's
reflection plus the conductor scaled by the coat's throughput, both at the
view angle in air) follows the physical coat on the metal seen from air
(:mod:`fitting.exports.seen_fit`). At eta_i 1 there is no coat: the
conductor alone, with the metal's own values in air. The node graph is the
implementation of a node definition of its own,
``ND_coated_metal_<name>_<id>_<eta>`` (:func:`fitting.exports.naming.element_stem`,
for example ``ND_coated_metal_Au_1a2b3c4d_eta1p33``: every fit and coat index
its own, so exports merge), whose inputs expose the roughness of the
metal and of the coat (perceptual, squared by ``roughness_anisotropy``) and
the coat index; the material instantiates it with the export's values.

The document's ``colorspace`` is the export's working space, and the
conductor's ``ior`` and ``extinction`` (and the values of their graph)
declare it too: a host whose target is that space converts nothing, and
the per-channel n, k are the ones fitted in it. The document and the
material carry the full fit id, the service version, the coat index and the
working space as attributes (:data:`fitting.exports._xml.IDENTITY_ATTRIBUTES`).

-   :func:`mtlx_document`: the document as text.

References
----------
MaterialX Specification 1.39, Physically Based Shading Nodes
(``conductor_bsdf``, ``dielectric_bsdf``, ``layer``, ``roughness_anisotropy``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from ._xml import add_input, document, identity_attributes, number, to_text, triple
from .naming import element_stem, identity
from .seen_fit import K_BOUNDS, N_BOUNDS, seen_fidelity
from .tool_layering import view_dependent
from .values import ExportValues

__all__ = ["MODEL_KIND", "mtlx_document"]

MODEL_KIND = (
    "conductor_bsdf (exact Fresnel per channel) under MaterialX's layer with a dielectric_bsdf coat, "
    "ior / extinction (affine in the facing 1 - cos theta where that fits better) fitted to the "
    "coated metal seen from air"
)


def _index_inputs(graph: ET.Element, metal: ET.Element, fitted: dict, space: str) -> None:
    """
    The conductor's ``ior`` and ``extinction``: constants, or where a slope
    is non-zero ``max(value + value_per_facing * facing, lower bound)`` with
    facing = clamp(1 + N.V) = 1 - cos theta (``viewdirection`` points from
    the eye to the surface), as :func:`fitting.exports.tool_layering.conductor_index`.
    Every colour value declares ``space``, the space the n, k were fitted in.
    """
    keys = (("ior", N_BOUNDS[0]), ("extinction", K_BOUNDS[0]))
    if not view_dependent(fitted):
        for key, _ in keys:
            add_input(metal, key, "color3", value=triple(fitted[key]), colorspace=space)
        return
    for kind, name in (("normal", "view_N"), ("viewdirection", "view_V")):
        add_input(ET.SubElement(graph, kind, name=name, type="vector3"), "space", "string", value="world")
    dot = ET.SubElement(graph, "dotproduct", name="view_NdotV", type="float")
    add_input(dot, "in1", "vector3", nodename="view_N")
    add_input(dot, "in2", "vector3", nodename="view_V")
    one_plus = ET.SubElement(graph, "add", name="view_facing_raw", type="float")
    add_input(one_plus, "in1", "float", nodename="view_NdotV")
    add_input(one_plus, "in2", "float", value="1")
    facing = ET.SubElement(graph, "clamp", name="view_facing", type="float")
    add_input(facing, "in", "float", nodename="view_facing_raw")
    for key, low in keys:
        scaled = ET.SubElement(graph, "multiply", name=f"{key}_slope", type="color3")
        add_input(scaled, "in1", "color3", value=triple(fitted[f"{key}_per_facing"]), colorspace=space)
        add_input(scaled, "in2", "float", nodename="view_facing")
        affine = ET.SubElement(graph, "add", name=f"{key}_affine", type="color3")
        add_input(affine, "in1", "color3", nodename=f"{key}_slope")
        add_input(affine, "in2", "color3", value=triple(fitted[key]), colorspace=space)
        bounded = ET.SubElement(graph, "max", name=f"{key}_at_view", type="color3")
        add_input(bounded, "in1", "color3", nodename=f"{key}_affine")
        add_input(bounded, "in2", "float", value=number(low))
        add_input(metal, key, "color3", nodename=f"{key}_at_view")


def mtlx_document(values: ExportValues) -> str:
    """
    The MaterialX document of ``values`` (one eta_i), UTF-8 text.

    The provenance (material, fit id, source, eta_i, model kind, generator)
    is an XML comment at the top and the ``doc`` string of the material.
    """
    ident = element_stem(values)
    node = f"coated_metal_{ident}"
    nodedef_name = f"ND_{node}"
    provenance = values.provenance(MODEL_KIND, seen_fidelity(values, "mtlx"))
    root = document(provenance, identity(values, with_pack=True))
    fitted = values.tools["mtlx"]
    coat_on = fitted["coat"]

    nodedef = ET.SubElement(
        root,
        "nodedef",
        name=nodedef_name,
        node=node,
        nodegroup="pbr",
        doc=(
            f"{values.name} under a clear coat: conductor_bsdf, dielectric_bsdf coat"
            if coat_on
            else f"{values.name}: conductor_bsdf, no coat"
        ),
    )
    add_input(
        nodedef,
        "base_roughness",
        "float",
        value=number(values.roughness),
        uimin="0.0",
        uimax="1.0",
        uiname="Metal Roughness",
    )
    if coat_on:
        add_input(
            nodedef,
            "coat_roughness",
            "float",
            value=number(values.coat_roughness),
            uimin="0.0",
            uimax="1.0",
            uiname="Coat Roughness",
        )
        add_input(
            nodedef,
            "coat_ior",
            "float",
            value=number(values.eta_i),
            uiname="Coat IOR",
            doc="The metal's values are fitted for this coat index; change it and re-export",
        )
    ET.SubElement(nodedef, "output", name="out", type="surfaceshader")

    graph = ET.SubElement(root, "nodegraph", name=f"NG_{node}", nodedef=nodedef_name)
    base_alpha = ET.SubElement(graph, "roughness_anisotropy", name="base_alpha", type="vector2")
    add_input(base_alpha, "roughness", "float", interfacename="base_roughness")
    metal = ET.SubElement(graph, "conductor_bsdf", name="metal", type="BSDF")
    _index_inputs(graph, metal, fitted, values.working_space)
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
        root,
        "surfacematerial",
        name=ident,
        type="material",
        doc="; ".join(f"{k}: {v}" for k, v in provenance.items()),
        **identity_attributes(identity(values, with_pack=True)),
    )
    add_input(material, "surfaceshader", "surfaceshader", nodename=f"{ident}_shader")
    return to_text(root)
