"""
Shading kernels on the GPU
==========================

The GLSL twins of :mod:`fitting.shading` evaluated into float32 targets and
read back, for the parity tests.

-   :func:`evaluate_brdf_grid`: ``glsl/microfacet.frag`` over a grid of view
    and light angles.
"""

from __future__ import annotations

import numpy as np

from fitting.shading.microfacet import check_mode

from .gl import GLState, RenderThread, check_gl_error

__all__ = ["evaluate_brdf_grid"]


def _read(fbo, index: int, width: int, height: int) -> np.ndarray:
    data = np.frombuffer(fbo.read(components=4, dtype="f4", attachment=index), np.float32)
    return data.reshape(height, width, 4)[..., :3].copy()


def _brdf_grid(state: GLState, mode, uniforms, grid, phi, width, height):
    ctx = state.ctx
    program, vao = state.program("microfacet.frag", {"CF_MODE": ("immersed", "coated").index(mode)})
    for name, value in uniforms.items():
        if name in program:
            program[name].value = value
    program["u_grid"].value = tuple(float(g) for g in grid)
    program["u_phi"].value = float(phi)
    fbo, targets = state.float_targets((width, height), 3)
    try:
        fbo.use()
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        out = tuple(_read(fbo, i, width, height) for i in range(3))
        check_gl_error(ctx)
    finally:
        state.release_targets(fbo, targets)
    return out


def evaluate_brdf_grid(
    thread: RenderThread,
    mode: str,
    F0,
    a,
    alpha,
    roughness: float,
    eta_i: float = 1.0,
    coat_roughness: float = 0.0,
    theta_v_axis: tuple[float, float, int] = (0.0, 1.5 / 63.0, 64),
    theta_l_axis: tuple[float, float, int] = (0.0, 1.5 / 63.0, 64),
    phi: float = np.pi,
):
    """
    ``cf_microfacet_immersed`` or ``cf_microfacet_coated`` over a grid: column
    i has theta_v = start + i step (view in the x-z plane), row j theta_l
    likewise, the light at azimuth ``phi`` (pi: the mirror plane). Angles in
    radians, computed in the shader in float32.

    Returns
    -------
    tuple
        The BRDF (rows, columns, 3) in 1/sr, and the float32 unit directions
        V and L (rows, columns, 3) the shader used.
    """
    check_mode(mode)
    uniforms = {
        "cf_F0": tuple(float(v) for v in F0),
        "cf_a": tuple(float(v) for v in a),
        "cf_alpha": tuple(float(v) for v in alpha),
        "cf_roughness": float(roughness),
        "cf_coat_roughness": float(coat_roughness),
        "cf_eta_i": float(eta_i),
    }
    v0, v_step, width = theta_v_axis
    l0, l_step, height = theta_l_axis
    grid = (v0, v_step, l0, l_step)
    return thread.call(_brdf_grid, mode, uniforms, grid, phi, int(width), int(height))
