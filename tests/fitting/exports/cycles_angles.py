"""
Run inside Blender's Python (``.venv-blender``): render a Blender export's
material with Cycles on a flat plane seen at given view angles, under a
uniform white world of strength 1, and print the mean linear RGB per angle
as JSON. Used by test_tool_layering_renders.py to check the numpy mirrors
of Cycles' layering.

    python cycles_angles.py EXPORT.py --output principled|conductor --angles 0,30,60 --samples 256 \
        [--working-space lin_rec709|acescg]

``--working-space acescg`` makes the file's working space ACEScg first
(Blender 5; the pixels are then linear ACEScg).
"""

from __future__ import annotations

import argparse
import json
import math
import runpy
import sys
import tempfile
from pathlib import Path

import bpy

SIZE = 4


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="cycles_angles.py")
    parser.add_argument("script", nargs="+")
    parser.add_argument("--output", default="principled", help="principled, conductor, or both comma-separated")
    parser.add_argument("--angles", default="0,30,60")
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--working-space", choices=("lin_rec709", "acescg"), default="lin_rec709")
    args = parser.parse_args(argv)
    outputs = args.output.split(",")
    if not set(outputs) <= {"principled", "conductor"}:
        parser.error(f"--output: principled and/or conductor, got {args.output!r}")
    angles = [float(a) for a in args.angles.split(",")]
    if len(args.script) == 1 and len(outputs) == 1:
        out = render_angles(args.script[0], outputs[0], angles, args.samples, args.working_space)
        print("CYCLES_ANGLES " + json.dumps(out))
        return 0
    # Several exports and outputs in one Blender process (one start-up):
    # {script: {output: {angle: rgb}}}, the outputs a script lacks left out.
    many: dict = {}
    for script in args.script:
        many[script] = {}
        for output in outputs:
            try:
                many[script][output] = render_angles(script, output, angles, args.samples, args.working_space)
            except (KeyError, ValueError, RuntimeError) as error:
                many[script][output] = {"error": str(error)}
    print("CYCLES_MANY " + json.dumps(many))
    return 0


def render_angles(
    script: str, output: str, angles: list[float], samples: int, working_space: str
) -> dict[str, list[float]]:
    """Mean linear RGB of the export's ``output`` on a plane at each view angle, in a fresh file."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if working_space == "acescg":
        bpy.ops.wm.set_working_color_space(working_space="ACEScg", convert_colors=False)
    namespace = runpy.run_path(script, run_name="coated_fresnel_export")
    material = namespace["build_material"]()
    namespace["use_output"](material, output)

    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=100.0)
    plane = bpy.context.active_object
    plane.data.materials.append(material)
    camera_data = bpy.data.cameras.new("camera")
    camera_data.type = "ORTHO"
    camera_data.ortho_scale = 0.05
    camera = bpy.data.objects.new("camera", camera_data)
    camera.location = (0.0, -10.0, 0.0)
    camera.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    world = bpy.data.worlds.new("white")
    scene.world = world
    if world.node_tree is None:
        world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    background.inputs["Strength"].default_value = 1.0
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.blur_glossy = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.max_bounces = 16
    scene.cycles.glossy_bounces = 16
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 1
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for angle in angles:
            # The plane's normal (sin t, -cos t, 0): at angle t to the camera's view.
            plane.rotation_euler = (math.pi / 2, 0.0, math.radians(angle))
            path = str(Path(tmp) / f"a{angle:g}.exr")
            scene.render.filepath = path
            bpy.ops.render.render(write_still=True)
            image = bpy.data.images.load(path)
            px = list(image.pixels)
            rgb = [sum(px[c::4]) / (len(px) // 4) for c in range(3)]
            bpy.data.images.remove(image)
            out[f"{angle:g}"] = rgb
    return out


if __name__ == "__main__":
    sys.exit(main(sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]))
