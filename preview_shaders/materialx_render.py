"""
MaterialX documents rendered headless
=====================================

MaterialX's own GLSL renderer (``MaterialX.PyMaterialXRenderGlsl``) needs an
X display. This renders a MaterialX document with the shader MaterialX's
GLSL generator makes for it (``MaterialX.PyMaterialXGenGlsl``, unchanged), on
the project's headless EGL context (:class:`preview_shaders.gl.RenderThread`):
a sphere in the preview's geometry (orthographic camera on +z, radius 0.45
of the image, see :mod:`preview_shaders.preview`) under a uniform white
environment of radiance 1 and no lights, so that a pixel shows the
directional albedo of the material at its cos theta (for a smooth conductor,
its Fresnel F(cos theta): the paper's validation setting).

-   :func:`materialx_glsl`: vertex and pixel shader of a document's material.
-   :func:`render_materialx`: the rendered sphere, linear, in the document's
    colour space, or in a target colour space through MaterialX's own colour
    management (its ``DefaultColorManagementSystem`` and the generator's
    ``targetColorSpaceOverride``, as a host working in that space sets them).
"""

from __future__ import annotations

import functools

import moderngl
import numpy as np

from fitting.exports.gltf import uv_sphere

from .gl import GLState, RenderThread, check_gl_error
from .preview import SPHERE_RADIUS

__all__ = ["ENVIRONMENT_SAMPLES", "materialx_glsl", "render_materialx"]

ENVIRONMENT_SAMPLES = 64
"""``u_envRadianceSamples``: MaterialX's filtered importance samples per pixel."""

# The sphere's tessellation: fine enough that interpolated normals are within
# ~1e-4 of the true ones inside the silhouette.
_SEGMENTS, _RINGS = 192, 96


@functools.cache
def _libraries():
    import MaterialX as mx

    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    return lib


def materialx_glsl(document_text: str, target_colorspace: str | None = None) -> tuple[str, str]:
    """
    The GLSL vertex and pixel shader MaterialX generates for the (only)
    material of a document, after checking the document is valid. With
    ``target_colorspace`` (a MaterialX colour space name, ``acescg``), the
    generator has MaterialX's default colour management system and that
    target: each colour input of another colour space is converted to it.

    Raises
    ------
    ValueError
        If the document does not parse, does not validate with the standard
        libraries, or does not hold exactly one material.
    """
    import MaterialX as mx
    import MaterialX.PyMaterialXGenGlsl as mx_gen_glsl
    import MaterialX.PyMaterialXGenShader as mx_gen_shader

    doc = mx.createDocument()
    try:
        mx.readFromXmlString(doc, document_text)
    except mx.ExceptionParseError as error:
        raise ValueError(f"`document_text` is not a MaterialX document: {error}") from None
    doc.importLibrary(_libraries())
    valid, message = doc.validate()
    if not valid:
        raise ValueError(f"`document_text` does not validate: {message.strip()}")
    materials = doc.getMaterialNodes()
    if len(materials) != 1:
        raise ValueError(f"`document_text` must hold one material, got {len(materials)}")
    generator = mx_gen_glsl.GlslShaderGenerator.create()
    context = mx_gen_shader.GenContext(generator)
    context.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    if target_colorspace is not None:
        cms = mx_gen_shader.DefaultColorManagementSystem.create(generator.getTarget())
        cms.loadLibrary(_libraries())
        generator.setColorManagementSystem(cms)
        context.getOptions().targetColorSpaceOverride = target_colorspace
    shader = generator.generate(materials[0].getName(), materials[0], context)
    return (shader.getSourceCode(mx_gen_shader.VERTEX_STAGE), shader.getSourceCode(mx_gen_shader.PIXEL_STAGE))


def _sphere_buffer() -> np.ndarray:
    positions, normals, indices = uv_sphere(_SEGMENTS, _RINGS)
    # Tangents around +y; at the poles, where that is undefined, any unit x.
    tangents = np.cross(np.array([0.0, 1.0, 0.0], np.float32), normals)
    length = np.linalg.norm(tangents, axis=1, keepdims=True)
    tangents = np.where(length > 1e-6, tangents / np.maximum(length, 1e-6), [1.0, 0.0, 0.0])
    vertices = np.hstack([positions, normals, tangents.astype(np.float32)]).astype(np.float32)
    return vertices, indices.astype(np.uint32)


def _render(state: GLState, vertex: str, pixel: str, size: int) -> np.ndarray:
    ctx = state.ctx
    program = ctx.program(vertex_shader=vertex, fragment_shader=pixel)
    vertices, indices = _sphere_buffer()
    vbo, ibo = ctx.buffer(vertices.tobytes()), ctx.buffer(indices.tobytes())
    names = ("i_position", "i_normal", "i_tangent")
    used = [name for name in names if name in program]
    layout = " ".join("3f" if name in used else "12x" for name in names)
    vao = ctx.vertex_array(program, [(vbo, layout, *used)], index_buffer=ibo, index_element_size=4)
    # Orthographic: x, y scaled so the unit sphere has the preview's radius;
    # z flipped into [-0.5, 0.5] so the front (z = 1) is nearest.
    scale = 2.0 * SPHERE_RADIUS
    projection = np.diag([scale, scale, -0.5, 1.0]).astype(np.float32)
    program["u_viewProjectionMatrix"].write(projection.T.tobytes())
    # Far up +z: V = normalize(eye - p) is +z to within 1e-4.
    program["u_viewPosition"].value = (0.0, 0.0, 1.0e4)
    white = ctx.texture((8, 4), 4, np.ones((4, 8, 4), np.float32).tobytes(), dtype="f4")
    white.use(0)
    for name, value in (
        ("u_envRadiance", 0),
        ("u_envIrradiance", 0),
        ("u_envRadianceMips", 1),
        ("u_envRadianceSamples", ENVIRONMENT_SAMPLES),
        ("u_envLightIntensity", 1.0),
        ("u_numActiveLightSources", 0),
    ):
        if name in program:
            program[name].value = value
    fbo, targets = state.float_targets((size, size), 1)
    depth = ctx.depth_renderbuffer((size, size))
    fbo_depth = ctx.framebuffer(color_attachments=targets, depth_attachment=depth)
    fbo_depth.use()
    ctx.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
    ctx.enable(moderngl.DEPTH_TEST)
    vao.render()
    ctx.disable(moderngl.DEPTH_TEST)
    image = np.frombuffer(fbo_depth.read(components=4, dtype="f4"), np.float32)
    check_gl_error(ctx)
    state._idle.use()
    for resource in (fbo_depth, depth, vao, vbo, ibo, white, program):
        resource.release()
    state.release_targets(fbo, targets)
    # GL's first row is the bottom one.
    return image.reshape(size, size, 4)[::-1].copy()


def render_materialx(
    document_text: str, size: int = 128, thread: RenderThread | None = None, target_colorspace: str | None = None
):
    """
    The sphere of a MaterialX document's material under a uniform white
    environment (see the module docstring).

    Parameters
    ----------
    document_text
        A MaterialX document with one material.
    size
        Pixels per side, 16..1024.
    thread
        A render thread to use; a new one (made and closed here) when None.
    target_colorspace
        ``None``: the document's own colour space; else the space the
        shader is generated for (:func:`materialx_glsl`).

    Returns
    -------
    tuple
        ``(image, coverage)``: (size, size, 3) float32, linear in the
        document's colour space (or ``target_colorspace``), top row first; (size, size) bool, where the
        sphere was drawn.
    """
    if not (isinstance(size, int) and 16 <= size <= 1024):
        raise ValueError(f"`size` must be an integer in [16, 1024], got {size!r}")
    vertex, pixel = materialx_glsl(document_text, target_colorspace)
    if thread is None:
        with RenderThread("materialx-render") as own:
            rgba = own.call(_render, vertex, pixel, size)
    else:
        rgba = thread.call(_render, vertex, pixel, size)
    return rgba[..., :3], rgba[..., 3] > 0.0
