"""
Full-screen shader evaluation
=============================

Each Fresnel variant of ``glsl/evaluate.frag`` evaluated over a grid of
(cos theta, eta_i) into a float32 target: the parity tests read it back and
compare it with numpy, the cost benchmark times it.

-   :data:`VARIANTS`: the variant names, in ``CF_VARIANT`` order.
-   :class:`ShaderInputs`: the uniforms every variant reads.
-   :func:`shader_inputs`: builds them from a coefficient pack.
-   :func:`padded_coefficients`: a degree-0/1 fit as 27 halves.
-   :func:`evaluate_grid`: renders one variant and reads it back.
-   :func:`decode_halves_in_shader`: the 27 coefficients as GLSL decodes them.
-   :func:`time_variants`: GL timer query, wall and CPU time of full-screen
    renders of several variants, interleaved.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fitting.models.baselines import equivalent_index, external_medium_F0, lazanyi_a
from fitting.models.coated_conductor import collapse_to_eta_i, lean_constants
from fitting.models.kinds import MODEL_KINDS, model_kind
from fitting.models.pack import PackedMaterial, halves_to_uint32

from .gl import GLState, RenderThread, check_gl_error, read_float_target, time_renders

__all__ = [
    "VARIANTS",
    "ShaderInputs",
    "padded_coefficients",
    "shader_inputs",
    "evaluate_grid",
    "decode_halves_in_shader",
    "TIMING_VARIANTS",
    "MODEL_VARIANTS",
    "time_variants",
    "constants_source",
    "CONSTANTS_SUFFIX",
]

VARIANTS = (
    "packed",
    "floats",
    "collapsed",
    "lazanyi",
    "schlick",
    "exact",
    "rgb_conductor",
    "lean",
    "collapsed_lean",
    "lazanyi_lean",
)
"""Model from float16 halves in uint32, model from float coefficients,
scene-specialised model (Eq. 1 only), adjusted Lazanyi, Schlick, exact RGB
conductor Fresnel from float n, k, the rgb-conductor model kind from its
6 float16 halves in 3 uint32, and the lean forms (per-material constants
from the CPU): the general model (``cf_coated_conductor_lean``), the
scene-specialised model (``cf_coated_conductor_eq1_lean``) and adjusted
Lazanyi (``cf_lazanyi_adjusted_lean``)."""

LAZANYI_SCENE = "lazanyi_scene"
FIXED = "fixed"
TIMING_VARIANTS = VARIANTS + (LAZANYI_SCENE, FIXED)
"""The variants and, for timing only (``CF_VARIANT`` 10 and 11 of
evaluate.frag): adjusted Lazanyi at the scene's constant eta_i with F0 and a
from the CPU (the like-for-like counterpart of the scene-specialised model),
and a pass with no Fresnel term (the fixed cost every variant pays)."""

MODEL_VARIANTS = {name: kind.shader_variant for name, kind in MODEL_KINDS.items() if kind.shader_variant}
"""The variant that evaluates a pack material of each model kind as shipped
(``ModelKind.shader_variant`` of the kinds registered at import: the variants are evaluate.frag's)."""


def padded_coefficients(coefficients) -> np.ndarray:
    """(3, 3, 3) float16 coefficients: a lower degree padded with zero powers
    (the same model, since 0 * t^j adds nothing)."""
    C = np.asarray(coefficients, dtype=np.float16)
    padded = np.zeros((3, 3, 3), dtype=np.float16)
    padded[:, :, : C.shape[2]] = C
    return padded


@dataclass(frozen=True)
class ShaderInputs:
    """
    Uniform values of the variants. ``words``: 14 uint32 (two halves each);
    ``coefficients``: the same 27 values as float32; ``eta_i_range``: fitted
    domain; ``collapsed``: (3, 3) F0/a/alpha rows at ``collapse_eta_i``;
    ``F0_air``, ``F82_air``: linear ACEScg reflectance in air at 0 and ~82
    degrees (adjusted Lazanyi; Schlick reads ``F0_air``); ``n``, ``k``:
    per-channel conductor index (exact RGB Fresnel); ``rgb_words``: the 3
    uint32 of an rgb-conductor's 6 halves (zero for a coated-conductor).
    """

    words: np.ndarray
    coefficients: np.ndarray
    eta_i_range: tuple[float, float]
    collapse_eta_i: float
    collapsed: np.ndarray
    F0_air: np.ndarray
    F82_air: np.ndarray
    n: np.ndarray
    k: np.ndarray
    rgb_words: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=np.uint32))


def shader_inputs(
    packed: PackedMaterial,
    collapse_eta_i: float = 1.5,
    F0_air=(0.0, 0.0, 0.0),
    F82_air=(0.0, 0.0, 0.0),
    n=None,
    k=None,
) -> ShaderInputs:
    """
    The uniforms of every variant for one material. For an rgb-conductor
    the coated-conductor uniforms are zero, ``rgb_words`` its packed halves,
    and ``n``, ``k`` default to its float16 values.
    """
    if model_kind(packed.model).shader_variant == "rgb_conductor":  # a variant of evaluate.frag
        C = packed.coefficients
        return ShaderInputs(
            words=np.zeros(14, dtype=np.uint32),
            coefficients=np.zeros(27, dtype=np.float32),
            eta_i_range=packed.eta_i_range,
            collapse_eta_i=float(collapse_eta_i),
            collapsed=np.zeros((3, 3)),
            F0_air=np.asarray(F0_air, dtype=np.float64),
            F82_air=np.asarray(F82_air, dtype=np.float64),
            n=C[0].astype(np.float64) if n is None else np.asarray(n, dtype=np.float64),
            k=C[1].astype(np.float64) if k is None else np.asarray(k, dtype=np.float64),
            rgb_words=halves_to_uint32(C),
        )
    halves = padded_coefficients(packed.coefficients)
    return ShaderInputs(
        words=halves_to_uint32(halves),
        coefficients=halves.astype(np.float32).ravel(),
        eta_i_range=packed.eta_i_range,
        collapse_eta_i=float(collapse_eta_i),
        collapsed=collapse_to_eta_i(packed.coefficients.astype(np.float64), collapse_eta_i, packed.eta_i_range)[..., 0],
        F0_air=np.asarray(F0_air, dtype=np.float64),
        F82_air=np.asarray(F82_air, dtype=np.float64),
        n=np.asarray((1.0, 1.0, 1.0) if n is None else n, dtype=np.float64),
        k=np.asarray((0.0, 0.0, 0.0) if k is None else k, dtype=np.float64),
    )


def _uniform_values(variant: str, inputs: ShaderInputs) -> dict:
    """The values of the uniforms ``variant`` reads (some others too), by name."""
    values: dict = {"cf_words": [int(w) for w in inputs.words]}
    # mat3 fills column by column: the layout order is already column-major.
    for name, m in zip(("cf_C_F0", "cf_C_a", "cf_C_alpha"), inputs.coefficients.reshape(3, 9)):
        values[name] = tuple(float(c) for c in m)
    values["cf_eta_i_range"] = tuple(float(v) for v in inputs.eta_i_range)
    if variant == "lean":
        P, t_map = lean_constants(inputs.coefficients.reshape(3, 3, 3), inputs.eta_i_range)
        # Column j of each mat3 is power j across the channels: P[p] row-major.
        for name, m in zip(("cf_P_F0", "cf_P_a", "cf_P_alpha"), P):
            values[name] = tuple(float(c) for c in m.ravel())
        values["cf_t_map"] = tuple(float(v) for v in t_map)
    if variant == "lazanyi_lean":
        values["cf_n_equivalent"] = tuple(float(v) for v in equivalent_index(inputs.F0_air))
        values["cf_a"] = tuple(float(v) for v in lazanyi_a(inputs.F0_air, inputs.F82_air))
    if variant in ("collapsed", "collapsed_lean"):
        for name, row in zip(("cf_F0", "cf_a", "cf_alpha"), inputs.collapsed):
            values[name] = tuple(float(v) for v in row)
    elif variant == LAZANYI_SCENE:
        # What a renderer precomputes when eta_i is constant for the scene.
        values["cf_F0"] = tuple(float(v) for v in external_medium_F0(inputs.F0_air, inputs.collapse_eta_i))
        values["cf_a"] = tuple(float(v) for v in lazanyi_a(inputs.F0_air, inputs.F82_air))
    elif variant != "lazanyi_lean":
        values["cf_F0"] = tuple(float(v) for v in inputs.F0_air)
    values["cf_F0_air"] = tuple(float(v) for v in inputs.F0_air)
    values["cf_F82_air"] = tuple(float(v) for v in inputs.F82_air)
    values["cf_n"] = tuple(float(v) for v in inputs.n)
    values["cf_k"] = tuple(float(v) for v in inputs.k)
    values["cf_rgb_words"] = [int(w) for w in inputs.rgb_words]
    return values


def _set_uniforms(program, variant: str, inputs: ShaderInputs) -> None:
    for name, value in _uniform_values(variant, inputs).items():
        if name in program:  # a variant's unused uniforms are compiled out
            program[name].value = value


_GLSL_TYPES = {2: "vec2", 3: "vec3", 9: "mat3"}


def constants_source(variant: str, inputs: ShaderInputs) -> str:
    """
    ``cf_constants.glsl`` for ``CF_CONSTANTS`` 1 of evaluate.frag: the
    values :func:`_set_uniforms` uploads, as GLSL constants instead (what an
    exported material snippet ships; a compiler folds work on them).
    Floats are written with Python's shortest repr, which the GLSL compiler
    rounds to the same float32 as an uploaded uniform.
    """
    lines = []
    for name, value in _uniform_values(variant, inputs).items():
        if isinstance(value, list):  # uint words
            items = ", ".join(f"{w}u" for w in value)
            lines.append(f"const uint {name}[{len(value)}] = uint[{len(value)}]({items});")
        else:
            items = ", ".join(repr(float(v)) for v in value)
            lines.append(f"const {_GLSL_TYPES[len(value)]} {name} = {_GLSL_TYPES[len(value)]}({items});")
    return "\n".join(lines) + "\n"


def _program(state: GLState, variant: str, inputs: ShaderInputs, constants: bool, write_inputs: int):
    """evaluate.frag for one (timing) variant, its inputs uniforms or constants."""
    source = constants_source(variant, inputs) if constants else ""
    program, vao = state.program(
        "evaluate.frag",
        {"CF_VARIANT": TIMING_VARIANTS.index(variant), "CF_WRITE_INPUTS": write_inputs, "CF_CONSTANTS": int(constants)},
        {"cf_constants.glsl": source},
    )
    if not constants:
        _set_uniforms(program, variant, inputs)
    return program, vao


def _check_variant(variant: str) -> int:
    if variant not in VARIANTS:
        raise ValueError(f"`variant` must be one of {', '.join(VARIANTS)}, got {variant!r}")
    return VARIANTS.index(variant)


def _evaluate_grid(state: GLState, variant, inputs, grid, width, height, constants):
    ctx = state.ctx
    _check_variant(variant)
    program, vao = _program(state, variant, inputs, constants, 1)
    program["u_grid"].value = tuple(float(g) for g in grid)
    fbo, targets = state.float_targets((width, height), 2)
    try:
        fbo.use()
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        F, inputs_out = (read_float_target(fbo, i, width, height) for i in range(2))
        check_gl_error(ctx)
    finally:
        state.release_targets(fbo, targets)
    return F[..., :3].copy(), inputs_out[..., 0].copy(), inputs_out[..., 1].copy()


def evaluate_grid(
    thread: RenderThread,
    variant: str,
    inputs: ShaderInputs,
    cos_theta_axis: tuple[float, float, int],
    eta_i_axis: tuple[float, float, int],
    constants: bool = False,
):
    """
    Evaluate one variant over a grid into a float32 target and read it back.
    With ``constants``, the material's values are compiled into the shader
    (:func:`constants_source`) instead of uploaded as uniforms.

    Parameters
    ----------
    cos_theta_axis, eta_i_axis
        (start, step, count): column i has cos theta = start + i step, row j
        eta_i = start + j step, computed in the shader in float32.

    Returns
    -------
    tuple
        ``F`` (count_eta, count_mu, 3) linear ACEScg float32, and the float32
        ``cos_theta`` and ``eta_i`` (count_eta, count_mu) the shader used.
    """
    mu0, mu_step, width = cos_theta_axis
    eta0, eta_step, height = eta_i_axis
    grid = (mu0, mu_step, eta0, eta_step)
    return thread.call(_evaluate_grid, variant, inputs, grid, int(width), int(height), bool(constants))


def _decode_halves(state: GLState, words):
    ctx = state.ctx
    program, vao = state.program("unpack_halves.frag")
    program["cf_words"].value = [int(w) for w in words]
    fbo, targets = state.float_targets((27, 1), 1)
    try:
        fbo.use()
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        data = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32)
        check_gl_error(ctx)
    finally:
        state.release_targets(fbo, targets)
    return data.reshape(27, 4)[:, 0].copy()


def decode_halves_in_shader(thread: RenderThread, words) -> np.ndarray:
    """The 27 float32 values ``cf_unpack_coefficients`` decodes from 14 words."""
    words = np.asarray(words, dtype=np.uint32)
    if words.shape != (14,):
        raise ValueError(f"`words` must hold 14 uint32, got shape {words.shape}")
    return thread.call(_decode_halves, words)


CONSTANTS_SUFFIX = "@const"
"""A timing variant name with this suffix has its inputs compiled in as constants."""


def _timing_program(state: GLState, name: str, inputs: ShaderInputs):
    """The full-screen program of one timing variant, inputs set."""
    variant = name.removesuffix(CONSTANTS_SUFFIX)
    return _program(state, variant, inputs, name.endswith(CONSTANTS_SUFFIX), 0)


def _time_variants(state: GLState, inputs, variants, width, height, rounds):
    ctx = state.ctx
    programs = {v: _timing_program(state, v, inputs) for v in variants}
    fbo, targets = state.float_targets((width, height), 1)
    for program, _ in programs.values():
        # mu over [0, 1] across the screen, eta_i over [1, 2.5] down it.
        program["u_grid"].value = (0.0, 1.0 / (width - 1), 1.0, 1.5 / (height - 1))
    try:
        fbo.use()
        return time_renders(ctx, {variant: vao for variant, (_, vao) in programs.items()}, rounds)
    finally:
        state.release_targets(fbo, targets)


def time_variants(
    thread: RenderThread,
    inputs: ShaderInputs,
    variants=TIMING_VARIANTS,
    width: int = 2560,
    height: int = 1440,
    rounds: int = 15,
) -> dict[str, np.ndarray]:
    """
    Time full-screen renders of ``variants`` (names of
    :data:`TIMING_VARIANTS`, each optionally with :data:`CONSTANTS_SUFFIX`:
    the material's values compiled in rather than uniforms) into an RGBA32F target, interleaved round by
    round so drifting machine load hits every variant alike, one warm-up
    render before each timed one.

    Returns
    -------
    dict
        Per variant, a (rounds, 3) array: GL timer query (ns), wall time (s)
        and process CPU time (s) of each timed render.
    """
    for variant in variants:
        if variant.removesuffix(CONSTANTS_SUFFIX) not in TIMING_VARIANTS:
            raise ValueError(f"`variants` must name {', '.join(TIMING_VARIANTS)}, got {variant!r}")
    return thread.call(_time_variants, inputs, tuple(variants), width, height, rounds)
