"""
Blender export
==============

A Python script that builds the material's node tree in Blender (4.2 or
later; rendered in CI with the ``bpy`` releases 4.2, 4.4 and 5.0:
``benchmarks/blender_matrix.py``). Run it in Blender's Text Editor
or ``blender --python FILE``; it calls :func:`build_material` in the script,
which makes a new material named ``<name>_<id>_<eta>``
(:func:`fitting.exports.naming.element_stem`) with two outputs:

-   the active ``Material Output``: a Principled BSDF, ``Metallic`` 1, with
    ``Base Color`` and ``Specular Tint`` the F0 and F82 tint (Cycles and
    EEVEE evaluate a metallic Principled BSDF with the F82-tint model),
    ``Coat Weight`` 1 and ``Coat IOR`` eta_i;
-   from Blender 5.0 (where its Physical Conductor is the exact Fresnel; the
    script makes only the first output before), a second ``Material Output
    (Physical Conductor)``: a Metallic BSDF in
    Physical Conductor mode with per-channel ``IOR`` and ``Extinction``
    (where the fit found it better, each affine in Layer Weight's Facing,
    1 - cos theta at blend 0.5: Vector Math ``MULTIPLY_ADD`` then
    ``MAXIMUM`` at the lower bound), under a coat made of a Glossy BSDF
    mixed in by the Fresnel of eta_i.
    Make it the active output to use it.

Both sets of values are fitted so that Cycles' own layering (the coat's
Fresnel plus the metal scaled by what the coat lets through, at the view
angle in air) follows the physical coat on the metal seen from air
(:mod:`fitting.exports.seen_fit`). At eta_i 1 there is no coat (``Coat
Weight`` 0; the Metallic BSDF straight into its output).

The values are those of one working space (``lin_rec709`` or ``acescg``,
:data:`fitting.exports.colour_space.WORKING_SPACES`). Before it makes
anything the script reads the file's working space (Blender 5's
``bpy.data.colorspace``; before 5.0 always linear Rec.709) and refuses, with
a ``RuntimeError`` that says which export to take, when it is not the one
the values were fitted in. Run as a script it assigns the material to the
active slot of the active mesh object (a new slot when it has none) and
changes nothing else.

The script uses only ``bpy`` and the standard library; its values are
literals, and its provenance is in the header comment and in the material's
custom properties: ``coated_fresnel`` (JSON), and ``coated_fresnel_fit_id``,
``coated_fresnel_version``, ``coated_fresnel_eta_i``,
``coated_fresnel_working_space``.

-   :func:`blender_script`: the script as text.
"""

from __future__ import annotations

import json

from .naming import carried_pack, element_stem, identity
from .seen_fit import K_BOUNDS, N_BOUNDS, seen_fidelity
from .values import ExportValues

__all__ = ["MODEL_KIND", "blender_script", "NODE_NAMES"]

MODEL_KIND = (
    "f82-tint (Principled BSDF with coat, active output) and exact conductor "
    "(Metallic BSDF, Physical Conductor, IOR / Extinction affine in Layer Weight's Facing where that "
    "fits better, under a Fresnel-mixed Glossy coat, second output), "
    "both fitted to the coated metal seen from air"
)

NODE_NAMES = {
    "principled": "Coated Metal (Principled)",
    "output": "Material Output",
    "metallic": "Metal (Physical Conductor)",
    "coat_glossy": "Coat (Physical Conductor)",
    "coat_fresnel": "Coat Fresnel (Physical Conductor)",
    "coat_mix": "Coated Metal (Physical Conductor)",
    "conductor_output": "Material Output (Physical Conductor)",
    "facing": "Facing (Physical Conductor)",
    "ior_affine": "IOR per Facing (Physical Conductor)",
    "ior_bound": "IOR (Physical Conductor)",
    "extinction_affine": "Extinction per Facing (Physical Conductor)",
    "extinction_bound": "Extinction (Physical Conductor)",
}
"""The names of the nodes the script makes (tests read the values back by them)."""

_SCRIPT = '''\
# Blender: a coated metal, made by coated-fresnel. Run in Blender's Text Editor
# or with `blender --python THIS_FILE`; needs only bpy.
#
{header}
import json

import bpy

MATERIAL_NAME = {material_name!r}
PROVENANCE = {provenance_json!r}
ETA_I = {eta_i!r}
COAT = {coat!r}
ROUGHNESS = {roughness!r}
IDENTITY = {identity!r}
# The fit's float16 model: a binary pack of one material, base64 (read back by coated-fresnel).
PACK = {pack!r}
# The working space every colour and n, k below is in, and Blender's name for it.
WORKING_SPACE = {working_space!r}
WORKING_SPACE_INTEROP_IDS = {{"lin_rec709": "lin_rec709_scene", "acescg": "lin_ap1_scene"}}
COAT_ROUGHNESS = {coat_roughness!r}
# F82-tint model in WORKING_SPACE, fitted to the coated metal seen from air
# under the Principled BSDF's coat.
BASE_COLOR = {F0!r}
SPECULAR_TINT = {tint!r}
# Physical Conductor n, k per channel in WORKING_SPACE, fitted likewise under
# the Fresnel-mixed coat: n = max(CONDUCTOR_IOR + CONDUCTOR_IOR_PER_FACING * Facing,
# IOR_LOWEST) with Facing = 1 - cos theta (Layer Weight, blend 0.5), k likewise.
CONDUCTOR_IOR = {n_rel!r}
CONDUCTOR_IOR_PER_FACING = {n_slope!r}
CONDUCTOR_EXTINCTION = {k_rel!r}
CONDUCTOR_EXTINCTION_PER_FACING = {k_slope!r}
IOR_LOWEST = {n_low!r}
EXTINCTION_LOWEST = {k_low!r}
NODE_NAMES = {node_names!r}
# The Physical Conductor output is made only where Blender evaluates the exact
# conductor Fresnel: from 5.0. Blender 4.2 has no Metallic BSDF, and 4.3-4.4's
# Physical Conductor departs from the exact Fresnel at low extinction (up to
# 10 Delta E off what 5.0 draws from the same n, k: benchmarks/blender_matrix.py);
# there the script makes the Principled output only.
CONDUCTOR_FROM = (5, 0, 0)


def _node(tree, kind, name, location):
    node = tree.nodes.new(kind)
    node.name = node.label = name
    node.location = location
    return node


def file_working_space():
    """The interop id of this file's working space (Blender 5); before 5.0 always linear Rec.709."""
    colorspace = getattr(bpy.data, "colorspace", None)
    if colorspace is None:
        return WORKING_SPACE_INTEROP_IDS["lin_rec709"]
    return colorspace.working_space_interop_id


def check_working_space():
    """Refuse a file whose working space is not the one the values were fitted in."""
    found = file_working_space()
    if found != WORKING_SPACE_INTEROP_IDS[WORKING_SPACE]:
        known = {{v: k for k, v in WORKING_SPACE_INTEROP_IDS.items()}}
        raise RuntimeError(
            f"coated-fresnel: this file's working space is {{found!r}}, but this material's "
            f"colours and n, k were fitted in {{WORKING_SPACE!r}}; export it again with "
            f"working_space={{known.get(found, 'lin_rec709 or acescg, after changing the file to one of them')}}"
        )


def build_material(name=MATERIAL_NAME):
    """Make the material and return it (a new one each call); refuses a file of another working space."""
    check_working_space()
    material = bpy.data.materials.new(name)
    if material.node_tree is None:  # Blender 4.x; from 5.0 every material has nodes
        material.use_nodes = True
    tree = material.node_tree
    tree.nodes.clear()
    material["coated_fresnel"] = PROVENANCE
    for key in ("fit_id", "service_version", "eta_i", "working_space"):
        material["coated_fresnel_" + ("version" if key == "service_version" else key)] = IDENTITY[key]
    if PACK is not None:
        material["coated_fresnel_pack"] = PACK

    principled = _node(tree, "ShaderNodeBsdfPrincipled", NODE_NAMES["principled"], (0, 300))
    principled.inputs["Base Color"].default_value = (*BASE_COLOR, 1.0)
    principled.inputs["Metallic"].default_value = 1.0
    principled.inputs["Roughness"].default_value = ROUGHNESS
    principled.inputs["Specular Tint"].default_value = (*SPECULAR_TINT, 1.0)
    principled.inputs["Coat Weight"].default_value = 1.0 if COAT else 0.0
    principled.inputs["Coat Roughness"].default_value = COAT_ROUGHNESS
    principled.inputs["Coat IOR"].default_value = ETA_I
    principled.inputs["Coat Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
    output = _node(tree, "ShaderNodeOutputMaterial", NODE_NAMES["output"], (300, 300))
    tree.links.new(principled.outputs["BSDF"], output.inputs["Surface"])
    output.is_active_output = True
    if tuple(bpy.app.version) < CONDUCTOR_FROM:
        return material

    metallic = _node(tree, "ShaderNodeBsdfMetallic", NODE_NAMES["metallic"], (0, -300))
    metallic.fresnel_type = "PHYSICAL_CONDUCTOR"
    metallic.distribution = "MULTI_GGX"
    metallic.inputs["IOR"].default_value = CONDUCTOR_IOR
    metallic.inputs["Extinction"].default_value = CONDUCTOR_EXTINCTION
    metallic.inputs["Roughness"].default_value = ROUGHNESS
    if any(CONDUCTOR_IOR_PER_FACING) or any(CONDUCTOR_EXTINCTION_PER_FACING):
        weight = _node(tree, "ShaderNodeLayerWeight", NODE_NAMES["facing"], (-600, -300))
        weight.inputs["Blend"].default_value = 0.5  # Facing = 1 - cos theta
        rows = (("IOR", "ior", CONDUCTOR_IOR, CONDUCTOR_IOR_PER_FACING, IOR_LOWEST, -150),
                ("Extinction", "extinction", CONDUCTOR_EXTINCTION, CONDUCTOR_EXTINCTION_PER_FACING,
                 EXTINCTION_LOWEST, -450))
        for socket, key, const, slope, lowest, y in rows:
            affine = _node(tree, "ShaderNodeVectorMath", NODE_NAMES[key + "_affine"], (-400, y))
            affine.operation = "MULTIPLY_ADD"
            affine.inputs[0].default_value = slope
            tree.links.new(weight.outputs["Facing"], affine.inputs[1])
            affine.inputs[2].default_value = const
            bound = _node(tree, "ShaderNodeVectorMath", NODE_NAMES[key + "_bound"], (-200, y))
            bound.operation = "MAXIMUM"
            tree.links.new(affine.outputs["Vector"], bound.inputs[0])
            bound.inputs[1].default_value = (lowest, lowest, lowest)
            tree.links.new(bound.outputs["Vector"], metallic.inputs[socket])
    glossy = _node(tree, "ShaderNodeBsdfAnisotropic", NODE_NAMES["coat_glossy"], (0, -650))
    glossy.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    glossy.inputs["Roughness"].default_value = COAT_ROUGHNESS
    fresnel = _node(tree, "ShaderNodeFresnel", NODE_NAMES["coat_fresnel"], (0, -100))
    fresnel.inputs["IOR"].default_value = ETA_I
    # The coat: its own Fresnel reflection, and the metal with what it lets through.
    mix = _node(tree, "ShaderNodeMixShader", NODE_NAMES["coat_mix"], (300, -300))
    tree.links.new(fresnel.outputs["Fac"], mix.inputs["Fac"])
    tree.links.new(metallic.outputs["BSDF"], mix.inputs[1])
    tree.links.new(glossy.outputs["BSDF"], mix.inputs[2])
    conductor_output = _node(
        tree, "ShaderNodeOutputMaterial", NODE_NAMES["conductor_output"], (600, -300)
    )
    if COAT:
        tree.links.new(mix.outputs["Shader"], conductor_output.inputs["Surface"])
    else:
        for node in (glossy, fresnel, mix):
            tree.nodes.remove(node)
        tree.links.new(metallic.outputs["BSDF"], conductor_output.inputs["Surface"])

    conductor_output.is_active_output = False
    output.is_active_output = True
    return material


def use_output(material, which):
    """Make ``"principled"`` or ``"conductor"`` the material's active output."""
    if which not in ("principled", "conductor"):
        raise ValueError(f"`which` must be 'principled' or 'conductor', got {{which!r}}")
    nodes = material.node_tree.nodes
    if which == "conductor" and NODE_NAMES["conductor_output"] not in nodes:
        raise RuntimeError(
            f"coated-fresnel: Blender {{bpy.app.version_string}} has no exact Physical Conductor "
            f"(from {{'.'.join(map(str, CONDUCTOR_FROM))}}); this material has its Principled output only"
        )
    nodes[NODE_NAMES["output"]].is_active_output = which == "principled"
    if NODE_NAMES["conductor_output"] in nodes:
        nodes[NODE_NAMES["conductor_output"]].is_active_output = which == "conductor"


if __name__ == "__main__":
    made = build_material()
    target = bpy.context.active_object if hasattr(bpy.context, "active_object") else None
    if target is not None and getattr(target, "type", None) == "MESH":
        # Only the active slot changes (a new slot when there is none): other
        # slots, their materials and the faces' assignments stay as they were.
        if len(target.material_slots) == 0:
            target.data.materials.append(made)
        else:
            target.material_slots[target.active_material_index].material = made
    print(f"coated-fresnel: made material {{made.name!r}}: {{json.loads(PROVENANCE)['material']}}")
'''


def _floats(values) -> tuple[float, ...]:
    return tuple(round(float(v), 6) for v in values)


def blender_script(values: ExportValues) -> str:
    """The Blender Python script of ``values``, UTF-8 text."""
    provenance = values.provenance(MODEL_KIND, seen_fidelity(values, "blender"))
    provenance["delta_E_2000_seen_physical_conductor"] = "mean {delta_E_mean:.3f}, max {delta_E_max:.3f}".format(
        **seen_fidelity(values, "blender-conductor")
    )
    principled, conductor = values.tools["blender"], values.tools["blender-conductor"]
    header = "\n".join(
        "# " + "".join(ch if 32 <= ord(ch) < 127 else " " for ch in f"{key}: {value}")
        for key, value in provenance.items()
    )
    return _SCRIPT.format(
        header=header,
        material_name=element_stem(values),
        identity=identity(values),
        pack=carried_pack(values),
        working_space=values.working_space,
        provenance_json=json.dumps(provenance, sort_keys=True),
        eta_i=round(values.eta_i, 6),
        coat=bool(principled["coat"]),
        roughness=round(values.roughness, 6),
        coat_roughness=round(values.coat_roughness, 6),
        F0=_floats(principled["base_color"]),
        tint=_floats(principled["specular_tint"]),
        n_rel=_floats(conductor["ior"]),
        k_rel=_floats(conductor["extinction"]),
        n_slope=_floats(conductor.get("ior_per_facing", (0.0,) * 3)),
        k_slope=_floats(conductor.get("extinction_per_facing", (0.0,) * 3)),
        n_low=N_BOUNDS[0],
        k_low=K_BOUNDS[0],
        node_names=NODE_NAMES,
    )
