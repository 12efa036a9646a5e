"""
Blender check and preview of a Blender export
=============================================

Runs inside Blender's Python (``bpy``; only ``bpy`` and the standard library
are imported, so it runs in ``.venv-blender``, not the project's
environment)::

    .venv-blender/bin/python fitting/exports/blender_preview.py EXPORT.py \
        --values values.json [--render sphere.png --size 64 --samples 8 --output principled]
    .venv-blender/bin/python fitting/exports/blender_preview.py EXPORT.gltf --gltf \
        --values values.json [--render sphere.png ...]

It starts from Blender's factory settings, executes the exported script and
calls its ``build_material()`` (or, with ``--gltf``, imports the glTF export
with Blender's bundled glTF importer), writes every input value of every node
of the material (as Blender stores them) to ``--values``, and optionally
renders a sphere with the material in Cycles on the CPU: a UV sphere (the
glTF's own sphere with ``--gltf``) in front of a camera, lit by a checkered
environment so that the reflection shows.
"""

from __future__ import annotations

import argparse
import json
import runpy
import sys

import bpy


def node_values(material) -> dict:
    """``{node name: {"type", "inputs": {name: value}, settings...}}`` of a material."""
    out = {}
    for node in material.node_tree.nodes:
        entry = {"type": node.bl_idname, "inputs": {}}
        for attr in ("fresnel_type", "distribution", "is_active_output", "operation"):
            if hasattr(node, attr):
                entry[attr] = getattr(node, attr)
        for socket in node.inputs:
            if socket.is_linked or not hasattr(socket, "default_value"):
                continue
            value = socket.default_value
            entry["inputs"][socket.identifier if socket.name in entry["inputs"] else socket.name] = (
                list(value) if hasattr(value, "__len__") and not isinstance(value, str) else value
            )
        out[node.name] = entry
    links = [
        [link.from_node.name, link.from_socket.name, link.to_node.name, link.to_socket.identifier]
        for link in material.node_tree.links
    ]
    custom = material.get("coated_fresnel")
    # The glTF importer keeps a material's extras as a property group.
    custom = custom.to_dict() if hasattr(custom, "to_dict") else custom
    return {"material": material.name, "nodes": out, "links": links, "custom": {"coated_fresnel": custom}}


def render_sphere(material, path: str, size: int, samples: int, sphere=None) -> None:
    """
    A Cycles CPU render to the PNG ``path`` of ``sphere`` (a new UV sphere
    with ``material`` when None) at the origin, radius 1.
    """
    scene = bpy.context.scene
    if sphere is None:
        bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=1.0)
        sphere = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        sphere.data.materials.append(material)
    camera_data = bpy.data.cameras.new("camera")
    camera_data.lens = 80.0
    camera = bpy.data.objects.new("camera", camera_data)
    camera.location = (0.0, -6.0, 0.0)
    camera.rotation_euler = (1.5707963, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera

    world = bpy.data.worlds.new("checker")
    world.use_nodes = True
    tree = world.node_tree
    tree.nodes.clear()
    coords = tree.nodes.new("ShaderNodeTexCoord")
    checker = tree.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 2.0
    checker.inputs["Color1"].default_value = (0.9, 0.9, 0.9, 1.0)
    checker.inputs["Color2"].default_value = (0.05, 0.05, 0.05, 1.0)
    background = tree.nodes.new("ShaderNodeBackground")
    output = tree.nodes.new("ShaderNodeOutputWorld")
    tree.links.new(coords.outputs["Generated"], checker.inputs["Vector"])
    tree.links.new(checker.outputs["Color"], background.inputs["Color"])
    tree.links.new(background.outputs["Background"], output.inputs["Surface"])
    scene.world = world

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 1
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="blender_preview.py")
    parser.add_argument("script", help="the exported Blender script (or glTF file with --gltf)")
    parser.add_argument("--gltf", action="store_true", help="import a glTF export instead")
    parser.add_argument("--values", required=True, help="write the node values here (JSON)")
    parser.add_argument("--render", help="render a sphere to this PNG")
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--samples", type=int, default=8)
    parser.add_argument("--output", choices=("principled", "conductor"), default="principled")
    args = parser.parse_args(argv)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    sphere = None
    if args.gltf:
        if bpy.ops.import_scene.gltf(filepath=args.script) != {"FINISHED"}:
            raise RuntimeError(f"Blender's glTF importer refused {args.script}")
        (sphere,) = [o for o in bpy.context.scene.objects if o.type == "MESH"]
        material = sphere.active_material
    else:
        namespace = runpy.run_path(args.script, run_name="coated_fresnel_export")
        material = namespace["build_material"]()
        namespace["use_output"](material, args.output)
    with open(args.values, "w") as f:
        json.dump(node_values(material), f, indent=1, sort_keys=True)
    if args.render:
        render_sphere(material, args.render, args.size, args.samples, sphere)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
