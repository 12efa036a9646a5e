"""
Shading kernels on the GPU
==========================

The GLSL twins of :mod:`fitting.shading` evaluated into float32 targets and
read back, for the parity tests.

-   :func:`evaluate_brdf_grid`: ``glsl/microfacet.frag`` over a grid of view
    and light angles.
-   :func:`upload_lut`: a :class:`fitting.shading.ibl.SplitSumLUT` as the 3D
    float texture ``cf_ibl.glsl`` reads (call on the render thread).
-   :func:`decode_lut_in_shader`: every texel as ``texelFetch`` returns it.
-   :func:`evaluate_split_sum_grid`: ``cf_split_sum_model`` over a grid of
    (NdotV, roughness).
-   :func:`time_split_sum`: GL timer query, wall and CPU time of full-screen
    split-sum passes (model, adjusted Lazanyi, Schlick, none), interleaved.
"""

from __future__ import annotations


import numpy as np

from fitting.shading.ibl import SplitSumLUT
from fitting.shading.microfacet import check_mode

from .gl import GLState, RenderThread, check_gl_error, read_float_target, time_renders

__all__ = [
    "evaluate_brdf_grid",
    "upload_lut",
    "decode_lut_in_shader",
    "evaluate_split_sum_grid",
    "SPLIT_SUM_VARIANTS",
    "time_split_sum",
]

SPLIT_SUM_VARIANTS = ("split_sum_model", "split_sum_lazanyi", "split_sum_schlick", "split_sum_fixed")
"""``CF_IBL_PASS`` 1 .. 4 of ``glsl/ibl.frag``."""


def _read(fbo, index: int, width: int, height: int) -> np.ndarray:
    return read_float_target(fbo, index, width, height)[..., :3].copy()


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


def upload_lut(state: GLState, lut: SplitSumLUT):
    """The LUT as an RGB32F 3D texture, (NdotV, roughness, alpha) = (x, y, z),
    nearest filtering (the shader interpolates)."""
    n_alpha, n_r, n_mu = lut.shape
    texture = state.ctx.texture3d(
        (n_mu, n_r, n_alpha), 3, np.ascontiguousarray(lut.data, dtype="f4").tobytes(), dtype="f4"
    )
    texture.filter = (state.ctx.NEAREST, state.ctx.NEAREST)
    return texture


def _lut_pass(state: GLState, lut: SplitSumLUT, defines, uniforms, size, slices):
    ctx = state.ctx
    program, vao = state.program("ibl.frag", defines)
    texture = upload_lut(state, lut)
    uniforms = {**uniforms, "cf_alpha_range": tuple(float(v) for v in lut.alpha_range), "cf_lut": 0}
    for name, value in uniforms.items():
        if name in program:
            program[name].value = value
    width, height = size
    fbo, targets = state.float_targets((width, height), 2)
    out = []
    try:
        texture.use(location=0)
        fbo.use()
        for k in slices:
            if "u_slice" in program:
                program["u_slice"].value = int(k)
            vao.render(mode=ctx.TRIANGLES, vertices=3)
            out.append(tuple(_read(fbo, i, width, height) for i in range(2)))
        check_gl_error(ctx)
    finally:
        state.release_targets(fbo, targets)
        texture.release()
    return out


def decode_lut_in_shader(thread: RenderThread, lut: SplitSumLUT) -> np.ndarray:
    """Every texel of ``lut`` read back through ``texelFetch``: float32 of
    the shape of ``lut.data``."""
    n_alpha, n_r, n_mu = lut.shape
    passes = thread.call(_lut_pass, lut, {"CF_IBL_PASS": 0}, {}, (n_mu, n_r), range(n_alpha))
    return np.stack([value for value, _ in passes])


def evaluate_split_sum_grid(
    thread: RenderThread,
    lut: SplitSumLUT,
    F0,
    a,
    alpha,
    NdotV_axis: tuple[float, float, int] = (0.0, 1.0 / 127.0, 128),
    roughness_axis: tuple[float, float, int] = (0.0, 1.0 / 127.0, 128),
):
    """
    ``cf_split_sum_model`` over a grid (column: NdotV = start + i step, row:
    roughness likewise, float32 in the shader).

    Returns
    -------
    tuple
        The albedo (rows, columns, 3), and the float32 NdotV and roughness
        (rows, columns) the shader used.
    """
    uniforms = {
        "cf_F0": tuple(float(v) for v in F0),
        "cf_a": tuple(float(v) for v in a),
        "cf_alpha": tuple(float(v) for v in alpha),
        "u_grid": (NdotV_axis[0], NdotV_axis[1], roughness_axis[0], roughness_axis[1]),
    }
    size = (int(NdotV_axis[2]), int(roughness_axis[2]))
    ((value, inputs),) = thread.call(_lut_pass, lut, {"CF_IBL_PASS": 1}, uniforms, size, [0])
    return value, inputs[..., 0].copy(), inputs[..., 1].copy()


def _time_split_sum(state: GLState, lut, per_variant, width, height, rounds):
    ctx = state.ctx
    texture = upload_lut(state, lut)
    programs = {}
    for index, variant in enumerate(SPLIT_SUM_VARIANTS, start=1):
        program, vao = state.program("ibl.frag", {"CF_IBL_PASS": index})
        values = {
            **per_variant[variant],
            "cf_alpha_range": tuple(float(v) for v in lut.alpha_range),
            "cf_lut": 0,
            "u_grid": (0.0, 1.0 / (width - 1), 0.0, 1.0 / (height - 1)),
        }
        for name, value in values.items():
            if name in program:
                program[name].value = value
        programs[variant] = vao
    fbo, targets = state.float_targets((width, height), 2)
    try:
        texture.use(location=0)
        fbo.use()
        return time_renders(ctx, programs, rounds)
    finally:
        state.release_targets(fbo, targets)
        texture.release()


def time_split_sum(
    thread: RenderThread,
    lut: SplitSumLUT,
    F0,
    a,
    alpha,
    F0_lazanyi,
    a_lazanyi,
    F0_air,
    width: int = 2560,
    height: int = 1440,
    rounds: int = 15,
) -> dict[str, np.ndarray]:
    """
    Time full-screen split-sum passes of :data:`SPLIT_SUM_VARIANTS` (NdotV
    across the screen, roughness down it, into two RGBA32F targets),
    interleaved round by round, one warm-up render before each timed one.
    The model gets ``F0, a, alpha`` (collapsed at the scene's eta_i),
    adjusted Lazanyi ``F0_lazanyi, a_lazanyi`` (from the CPU), Schlick
    ``F0_air``.

    Returns
    -------
    dict
        Per variant a (rounds, 3) array: GL timer query (ns), wall (s), CPU (s).
    """

    def vec3(values):
        return tuple(float(v) for v in values)

    per_variant = {
        "split_sum_model": {"cf_F0": vec3(F0), "cf_a": vec3(a), "cf_alpha": vec3(alpha)},
        "split_sum_lazanyi": {"cf_F0": vec3(F0_lazanyi), "cf_a": vec3(a_lazanyi)},
        "split_sum_schlick": {"cf_F0": vec3(F0_air)},
        "split_sum_fixed": {},
    }
    return thread.call(_time_split_sum, lut, per_variant, int(width), int(height), int(rounds))
