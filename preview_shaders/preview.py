"""
Preview sphere
==============

The headless preview the service and the editor show: a smooth sphere under
a uniform white sky (the paper's validation setting, where the sphere shows
F(cos theta) directly) or in a studio, drawn by ``glsl/preview.frag`` on one
dedicated render thread, with an optional split view (Vernooij 2024,
Figure 2): left the model, right adjusted Lazanyi or the spectral reference.

Service entry point (thread-safe; the GL work runs on the renderer's own
thread, the spectral reference and metrics on the caller's)::

    renderer = PreviewRenderer()
    result = renderer.render_preview(
        packed,                 # fitting.models.pack.PackedMaterial (float16 coefficients)
        nk,                     # fitting.optics.nk.SpectralNK or None; needed by
                                # compare="lazanyi" | "reference"
        eta_i=1.5,              # coating index, [1, 3]
        size=512,               # pixels per side, 64..2048
        compare="none",         # "none" | "lazanyi" | "reference"
        environment="white_sky",# "white_sky" | "studio" | "outdoor"
        roughness=0.0,          # GGX perceptual roughness, [0, 1]
        mode="immersed",        # "immersed" | "coated" (a clear coat of index eta_i)
        coat_roughness=0.0,     # the coat's roughness (mode="coated"), [0, 1]
    )
    result.png                  # bytes: the (split) view, 8-bit sRGB PNG
    result.image                # (size, size, 3) float32 linear ACEScg
    renderer.close()

:class:`PreviewResult` also holds the full model image, the comparison image,
cos theta per pixel and, with compare="reference", the Delta E 2000 and FLIP
maps between model and reference with their means over the sphere.

Geometry: orthographic camera on +z, sphere centre at the image centre,
radius 0.45 size; pixel (x, y) (top row first) has its centre at
(x + 0.5, size - y - 0.5) in GL window coordinates; on the sphere
cos theta = N.z = sqrt(1 - r^2) with r the distance from the centre over the
radius.

-   :data:`COMPARISONS`, :data:`ENVIRONMENTS`: the accepted values (and
    their checks, and the sphere's geometry: :mod:`preview_shaders.views`,
    re-exported).
-   :class:`PreviewRenderer`, :class:`PreviewResult`.
-   :func:`reference_image`, :func:`reference_table`, :func:`difference_maps`:
    the spectral reference of a view and the maps against it
    (:mod:`preview_shaders.reference`, re-exported).
-   How each model kind is drawn: :mod:`preview_shaders.kinds` (the kind's
    ``preview_call`` in ``cf_preview_model``, one program per kind).
Rough spheres and the coated mode are drawn by
``glsl/preview_rough.frag`` through the split sum with a prefiltered
environment (:mod:`preview_shaders.rough`).

-   :func:`sphere_cos_theta`: cos theta per pixel from the geometry, in numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fitting.domain import check_eta_i
from fitting.models.baselines import baseline_inputs
from fitting.models.kinds import model_kind
from fitting.models.pack import PackedMaterial

from .display import ACEScg_to_sRGB, encode_png, to_uint8
from .gl import GLState, RenderThread, check_gl_error, read_float_target
from .kinds import PREVIEW_MODEL_FILE, padded_words, preview_model_source, preview_words
from .reference import (
    REFERENCE_TABLE_SIZE,
    REFERENCE_TABLE_TOLERANCE,
    difference_maps,
    reference_image,
    reference_table,
)
from .views import (
    COMPARISONS,
    ENVIRONMENTS,
    ETA_I_LIMITS,
    MODES,
    SIZE_RANGE,
    SPHERE_RADIUS,
    check_choice,
    check_size,
    check_unit,
    sphere_cos_theta,
)

__all__ = [
    "COMPARISONS",
    "ENVIRONMENTS",
    "MODES",
    "SIZE_RANGE",
    "ETA_I_LIMITS",
    "SPHERE_RADIUS",
    "PreviewResult",
    "PreviewRenderer",
    "reference_image",
    "reference_table",
    "REFERENCE_TABLE_SIZE",
    "REFERENCE_TABLE_TOLERANCE",
    "difference_maps",
    "sphere_cos_theta",
    "padded_words",
]


@dataclass
class PreviewResult:
    """
    One preview. Images are (size, size, 3) float32 linear ACEScg, top row
    first; ``png`` is ``image`` through the display transform
    (:mod:`preview_shaders.display`).

    ``image``: the view (split when ``compare`` is not "none");
    ``model``: the model over the whole sphere; ``comparison``: adjusted
    Lazanyi or the reference over the whole sphere (None for "none");
    ``cos_theta``, ``mask``: cos theta per pixel and the sphere;
    ``radiance``: the environment radiance each pixel sees;
    ``delta_E``, ``flip``: maps model vs reference (compare="reference"),
    with ``delta_E_mean``, ``flip_mean`` over the sphere's pixels.
    """

    image: np.ndarray
    png: bytes
    model: np.ndarray
    comparison: np.ndarray | None
    cos_theta: np.ndarray
    mask: np.ndarray
    radiance: np.ndarray
    compare: str
    eta_i: float
    environment: str
    delta_E: np.ndarray | None = None
    delta_E_mean: float | None = None
    flip: np.ndarray | None = None
    flip_mean: float | None = None
    roughness: float = 0.0
    mode: str = "immersed"
    coat_roughness: float = 0.0


def _render_layers(state: GLState, model, eta_i_range, F0_air, F82_air, eta_i, size, environment, split_column):
    """On the render thread: colour, geometry and radiance, top row first."""
    ctx = state.ctx
    program, vao = state.program(
        "preview.frag", sources={PREVIEW_MODEL_FILE: preview_model_source(model_kind(model[0]))}
    )
    _, words = model
    uniforms = {
        "u_centre": (0.5 * size, 0.5 * size),
        "u_radius": SPHERE_RADIUS * size,
        "u_split_column": float(split_column),
        "u_environment": ENVIRONMENTS.index(environment),
        "u_eta_i": eta_i,
        "cf_eta_i_range": tuple(float(v) for v in eta_i_range),
        "cf_F0_air": tuple(float(v) for v in F0_air),
        "cf_F82_air": tuple(float(v) for v in F82_air),
    }
    for name, value in uniforms.items():
        # A kind that does not read a uniform (the rgb-conductor's domain) leaves it to the compiler.
        if name in program:
            program[name].value = value
    # ... and of the words it reads fewer than 14 (the array is trimmed).
    uniform = program["cf_words"]
    uniform.value = [int(w) for w in words[: uniform.array_length]]
    fbo, targets = state.float_targets((size, size), 3)
    try:
        fbo.use()
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        layers = [read_float_target(fbo, i, size, size)[::-1].copy() for i in range(3)]
        check_gl_error(ctx)
    finally:
        state.release_targets(fbo, targets)
    return layers


class PreviewRenderer:
    """
    Renders previews; owns (or shares) one :class:`RenderThread`. Thread-safe:
    the GL work of concurrent calls is serialised on that thread.
    """

    def __init__(self, thread: RenderThread | None = None) -> None:
        self._owns_thread = thread is None
        self.thread = thread or RenderThread()

    def close(self) -> None:
        if self._owns_thread:
            self.thread.close()

    def __enter__(self) -> "PreviewRenderer":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def render_preview(
        self,
        packed: PackedMaterial,
        nk=None,
        eta_i: float = 1.5,
        size: int = 512,
        compare: str = "none",
        environment: str = "white_sky",
        step_nm: float = 1.0,
        differences: bool = True,
        roughness: float = 0.0,
        mode: str = "immersed",
        coat_roughness: float = 0.0,
    ) -> PreviewResult:
        """
        Render the preview sphere (see the module docstring). With
        compare="reference", ``differences`` adds the Delta E 2000 and FLIP
        maps (:func:`difference_maps`; they cost several times the render, so
        a caller that only shows the PNG passes False).

        Raises
        ------
        ValueError
            For ``size`` outside [64, 2048], ``eta_i`` outside [1, 3], an
            unknown ``compare`` or ``environment``, a ``packed`` that is not a
            PackedMaterial, or a comparison without ``nk``; ``roughness``
            or ``coat_roughness`` outside [0, 1], an unknown ``mode``, or a
            rough / coated view of a model kind other than coated-conductor.

        ``roughness`` = 0 with ``mode`` = "immersed" is the smooth sphere of
        ``preview.frag`` (the paper's validation view, unchanged); any other
        combination is drawn by ``preview_rough.frag``
        (:mod:`preview_shaders.rough`): the split sum with the environment
        prefiltered at the roughness, the comparison under the same lighting.
        """
        if not isinstance(packed, PackedMaterial):
            raise ValueError(f"`packed` must be a PackedMaterial, got {type(packed).__name__}")
        size = check_size(size)
        eta_i = check_eta_i(eta_i)
        compare = check_choice("compare", compare, COMPARISONS)
        environment = check_choice("environment", environment, ENVIRONMENTS)
        if compare != "none" and nk is None:
            raise ValueError(f"`nk` is needed for compare={compare!r}: the material's n, k")
        roughness = check_unit("roughness", roughness)
        coat_roughness = check_unit("coat_roughness", coat_roughness)
        mode = check_choice("mode", mode, MODES)
        if roughness > 0.0 or mode != "immersed":
            if not model_kind(packed.model).split_sum:
                raise ValueError(
                    f"`roughness` > 0 and `mode` coated need a model kind with the split-sum lookup "
                    f"(coated-conductor), got {packed.model!r}"
                )
            return self._render_rough(
                packed, nk, eta_i, size, compare, environment, step_nm, roughness, mode, coat_roughness, differences
            )

        baseline = baseline_inputs(nk) if nk is not None else None
        F0_air = baseline["F0_air"] if baseline else np.zeros(3)
        F82_air = baseline["F82_air"] if baseline else np.zeros(3)
        common = (_model_words(packed), packed.eta_i_range, F0_air, F82_air, eta_i, size, environment)
        model, geometry, radiance = self.thread.call(_render_layers, *common, size)
        mask = geometry[..., 1] > 0.5
        cos_theta = geometry[..., 0]
        model = model[..., :3]
        comparison = None
        if compare == "lazanyi":
            comparison = self.thread.call(_render_layers, *common, 0)[0][..., :3]
        elif compare == "reference":
            comparison = reference_image(nk, cos_theta, mask, radiance, eta_i, step_nm)
        image = model.copy()
        if comparison is not None:
            # The same rule as the shader's split: columns from size // 2 on.
            image[:, size // 2 :] = comparison[:, size // 2 :]
        result = PreviewResult(
            image=image,
            png=encode_png(to_uint8(ACEScg_to_sRGB(image))),
            model=model,
            comparison=comparison,
            cos_theta=cos_theta,
            mask=mask,
            radiance=radiance[..., :3],
            compare=compare,
            eta_i=eta_i,
            environment=environment,
        )
        if compare == "reference" and differences:
            (result.delta_E, result.delta_E_mean, result.flip, result.flip_mean) = difference_maps(
                model, comparison, mask
            )
        return result

    def _render_rough(
        self, packed, nk, eta_i, size, compare, environment, step_nm, roughness, mode, coat_roughness, differences=True
    ) -> PreviewResult:
        from fitting.shading.ibl import default_lut

        from .rough import prefiltered_environment, render_rough_layers, rough_reference_image

        baseline = baseline_inputs(nk) if nk is not None else None
        lut = default_lut()
        prefiltered = prefiltered_environment(self.thread, ENVIRONMENTS.index(environment))
        uniforms = {
            "u_centre": (0.5 * size, 0.5 * size),
            "u_radius": SPHERE_RADIUS * size,
            "u_environment": ENVIRONMENTS.index(environment),
            "u_eta_i": eta_i,
            "u_mode": MODES.index(mode),
            "u_roughness": roughness,
            "u_coat_roughness": coat_roughness,
            "cf_words": [int(w) for w in padded_words(packed)],
            "cf_eta_i_range": tuple(float(v) for v in packed.eta_i_range),
            "cf_F0_air": tuple(float(v) for v in (baseline["F0_air"] if baseline else np.zeros(3))),
            "cf_F82_air": tuple(float(v) for v in (baseline["F82_air"] if baseline else np.zeros(3))),
        }

        def layers(split_column):
            return self.thread.call(
                render_rough_layers,
                lut.data,
                lut.alpha_range,
                prefiltered,
                {**uniforms, "u_split_column": float(split_column)},
                size,
            )

        model, geometry, radiance, coat_radiance = layers(size)
        mask = geometry[..., 1] > 0.5
        cos_theta = geometry[..., 0]
        model = model[..., :3]
        comparison = None
        if compare == "lazanyi":
            comparison = layers(0)[0][..., :3]
        elif compare == "reference":
            comparison = rough_reference_image(
                nk, cos_theta, mask, radiance, coat_radiance, eta_i, roughness, mode, coat_roughness, step_nm
            )
        image = model.copy()
        if comparison is not None:
            image[:, size // 2 :] = comparison[:, size // 2 :]
        result = PreviewResult(
            image=image,
            png=encode_png(to_uint8(ACEScg_to_sRGB(image))),
            model=model,
            comparison=comparison,
            cos_theta=cos_theta,
            mask=mask,
            radiance=radiance[..., :3],
            compare=compare,
            eta_i=eta_i,
            environment=environment,
            roughness=roughness,
            mode=mode,
            coat_roughness=coat_roughness,
        )
        if compare == "reference" and differences:
            (result.delta_E, result.delta_E_mean, result.flip, result.flip_mean) = difference_maps(
                model, comparison, mask
            )
        return result

    def render_split_in_shader(self, packed, nk, eta_i, size, environment="white_sky"):
        """The model | adjusted Lazanyi split drawn by the shader itself (one
        pass), float32 linear ACEScg, top row first."""
        size = check_size(size)
        eta_i = check_eta_i(eta_i)
        environment = check_choice("environment", environment, ENVIRONMENTS)
        baseline = baseline_inputs(nk)
        layers = self.thread.call(
            _render_layers,
            _model_words(packed),
            packed.eta_i_range,
            baseline["F0_air"],
            baseline["F82_air"],
            eta_i,
            size,
            environment,
            size // 2,
        )
        return layers[0][..., :3]


def _model_words(packed: PackedMaterial) -> tuple[str, np.ndarray]:
    """The kind and the preview's uniform words (:func:`preview_shaders.kinds.preview_words`)."""
    return packed.model, preview_words(packed)
