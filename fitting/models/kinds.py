"""
Model kinds
===========

The one registry of model kinds, as colour-science's ``DELTA_E_METHODS``:
every module that treats a kind differently asks its :class:`ModelKind`
here (the pack, the fits, the shaders, the preview, the downloads, the
command line and the service); none compares kind names.

-   :class:`ModelKind`: a kind's name, pack code, parameters and shape,
    coefficient check, numpy evaluation, GLSL / HLSL functions and templates,
    how the preview draws it.
-   :data:`MODEL_KINDS`: name to :class:`ModelKind`, in pack-code order:
    ``coated-conductor`` (Vernooij 2024, Eq. 1 and 2; coefficients
    (3, 3, d + 1), d in 0-2) and ``rgb-conductor`` (the exact Fresnel
    equations per channel of the relative index (n + i k)/eta_i;
    coefficients (2, 3)).
-   :data:`DEFAULT_MODEL`: ``coated-conductor``.
-   :func:`register_model_kind`, :func:`unregister_model_kind`.
-   :func:`model_kind`: the :class:`ModelKind` of a name, or a ``ValueError``.
-   :func:`check_model`: a kind name, or a ``ValueError`` naming the rule.
-   :func:`check_model_coefficients`: coefficients valid for a kind.
-   :func:`model_ACEScg`: a kind's reflectance, linear ACEScg.
-   :func:`coefficient_count`: float16 numbers per material.

A third kind is one module per layer and one registration each (see
``docs/architecture.md``, "Adding a model kind"): its numpy model beside
the others, a :class:`ModelKind` given to :func:`register_model_kind`, its
fit given to :func:`fitting.fits.kinds.register_fit_kind`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .coated_conductor import check_coefficients, coated_conductor_model
from .coated_conductor import PARAMETERS as COATED_PARAMETERS
from .rgb_conductor import NK_PARAMETERS, check_rgb_conductor_coefficients, rgb_conductor_model

__all__ = [
    "ModelKind",
    "MODEL_KINDS",
    "DEFAULT_MODEL",
    "PREVIEW_WORDS",
    "register_model_kind",
    "unregister_model_kind",
    "model_kind",
    "kind_of_code",
    "check_model",
    "check_model_coefficients",
    "model_ACEScg",
    "coefficient_count",
]

PREVIEW_WORDS = 14
"""uint32 words of the preview's coefficient uniform ``cf_words`` (27 halves, two per word)."""


@dataclass(frozen=True)
class ModelKind:
    """
    One model kind.

    Attributes
    ----------
    name
        The kind's name in packs, the API and ``--model``.
    code
        The pack's kind byte (unique; 0 is the only kind of pack version 1).
    description
        One line for people.
    parameters
        Names of the coefficient rows, each one value per channel R, G, B.
    max_degree
        Highest polynomial degree in t of each value; 0 for a kind whose
        coefficients have no power axis (shape (P, 3)); a kind with
        ``max_degree`` > 0 has coefficients (P, 3, degree + 1).
    check
        ``check(coefficients) -> float64 array``: shape, finiteness, signs
        (``ValueError`` naming the rule).
    evaluate
        ``evaluate(cos_theta, eta_i, coefficients, eta_i_range) -> (..., 3)``
        linear ACEScg (a physics kernel: never raises on numbers).
    glsl_file, hlsl_file
        The kind's shader source: a file name in ``preview_shaders/glsl/``
        (HLSL: ``fitting/exports/templates/``) or an absolute path.
    glsl_function
        The function the snippet's material blocks call (its
        reachable helpers are kept, the rest dropped).
    preview_call
        GLSL expression of the kind's reflectance in the preview from
        ``NdotV``, ``eta_i``, ``eta_i_range`` and ``words`` (uint[14], the
        float16 coefficients two per word as :func:`fitting.models.pack.halves_to_uint32`
        gives them, zero-padded).
    material_template
        Template stem (``<stem>.glsl`` / ``<stem>.hlsl`` in
        ``fitting/exports/templates/``, or an absolute path without suffix) of a
        download's material block; it is given each parameter's values
        (padded to ``max_degree``) as ``${<parameter>}``.
    split_sum
        Whether the kind has the split-sum lookup (``cf_ibl``): downloads
        carry it, and the rough and coated previews draw the kind.
    shader_variant, collapsed_variant
        The ``evaluate.frag`` variant that evaluates the kind as shipped, and
        the one for degree 0 (None: the same).
    live_solver
        The browser editor's own solver of the kind's live step (a name of
        its table in ``static/editor/live_page.js``: ``"polynomial"``, the
        coated polynomial with the [0, 1] rule, or ``"exact-fresnel"``, per
        channel n, k), or None: the editor asks the server's live step.
    """

    name: str
    code: int
    description: str
    parameters: tuple[str, ...]
    max_degree: int
    check: Callable[[Any], np.ndarray]
    evaluate: Callable[..., np.ndarray]
    glsl_file: str
    hlsl_file: str
    glsl_function: str
    preview_call: str
    material_template: str
    split_sum: bool = False
    shader_variant: str | None = None
    collapsed_variant: str | None = None
    live_solver: str | None = None

    @property
    def polynomial(self) -> bool:
        """Whether the coefficients have a power axis (shape (P, 3, degree + 1))."""
        return self.max_degree > 0

    def shape(self, degree: int = 0) -> tuple[int, ...]:
        """The coefficients' shape at ``degree`` (ignored without a power axis)."""
        P = len(self.parameters)
        return (P, 3, degree + 1) if self.polynomial else (P, 3)

    def degree_of(self, coefficients) -> int:
        """The polynomial degree of ``coefficients`` of this kind (0 without a power axis)."""
        return int(np.shape(coefficients)[2]) - 1 if self.polynomial else 0

    def count(self, degree: int = 0) -> int:
        """Float16 numbers per material."""
        return int(np.prod(self.shape(degree)))

    def variant(self, degree: int) -> str | None:
        """The ``evaluate.frag`` variant of a material of this kind and degree."""
        if degree == 0 and self.collapsed_variant is not None:
            return self.collapsed_variant
        return self.shader_variant


MODEL_KINDS: dict[str, ModelKind] = {}
"""The registered kinds by name, in the order registered (pack codes ascending)."""
DEFAULT_MODEL = "coated-conductor"


def register_model_kind(kind: ModelKind) -> ModelKind:
    """
    Add ``kind`` to :data:`MODEL_KINDS`.

    Raises
    ------
    ValueError
        When its name or pack code is taken, or its shape or preview does not fit.
    """
    if not isinstance(kind, ModelKind):
        raise ValueError(f"`kind` must be a ModelKind, got {type(kind).__name__}")
    if kind.name in MODEL_KINDS:
        raise ValueError(f"model kind {kind.name!r} is already registered")
    if any(k.code == kind.code for k in MODEL_KINDS.values()) or not 0 <= kind.code <= 255:
        raise ValueError(f"`code` of model kind {kind.name!r} must be a free byte, got {kind.code}")
    if not 0 <= kind.max_degree <= 2 or not kind.parameters:
        raise ValueError(f"model kind {kind.name!r} must have parameters and `max_degree` 0-2")
    if kind.count(kind.max_degree) > 2 * PREVIEW_WORDS:
        raise ValueError(f"model kind {kind.name!r} must fit {2 * PREVIEW_WORDS} float16 numbers")
    MODEL_KINDS[kind.name] = kind
    return kind


def unregister_model_kind(name: str) -> None:
    """Remove a kind registered by :func:`register_model_kind` (tests of a toy kind)."""
    MODEL_KINDS.pop(name, None)


def model_kind(model) -> ModelKind:
    """The :class:`ModelKind` named ``model``; otherwise ``ValueError``."""
    kind = MODEL_KINDS.get(model) if isinstance(model, str) else None
    if kind is None:
        raise ValueError(f"`model` must be one of {', '.join(MODEL_KINDS)}, got {model!r}")
    return kind


def kind_of_code(code: int) -> ModelKind:
    """The kind of a pack's kind byte; ``ValueError`` for an unknown one."""
    for kind in MODEL_KINDS.values():
        if kind.code == code:
            return kind
    raise ValueError(
        f"`data` has model kind code {code}, must be one of {', '.join(str(k.code) for k in MODEL_KINDS.values())}"
    )


def check_model(model) -> str:
    """``model`` if it is one of :data:`MODEL_KINDS`; otherwise ``ValueError``."""
    return model_kind(model).name


def check_model_coefficients(model: str, coefficients) -> np.ndarray:
    """The coefficients of kind ``model`` as float64, validated (shape, finiteness, signs)."""
    return model_kind(model).check(coefficients)


def model_ACEScg(model: str, cos_theta, eta_i, coefficients, eta_i_range) -> np.ndarray:
    """
    Reflectance of kind ``model`` at (cos theta, eta_i), linear ACEScg,
    shape ``broadcast(cos_theta, eta_i).shape + (3,)``. ``eta_i_range`` is
    the fitted domain (the coated-conductor model's t; the rgb-conductor
    does not depend on it).
    """
    return model_kind(model).evaluate(cos_theta, eta_i, coefficients, eta_i_range)


def coefficient_count(model: str, degree: int = 2) -> int:
    """Float16 numbers per material of kind ``model`` (and polynomial degree)."""
    return model_kind(model).count(degree)


register_model_kind(
    ModelKind(
        name="coated-conductor",
        code=0,
        description="Vernooij (2024) coated-conductor model, Eq. 1 and 2: F0, a, alpha per channel, "
        "polynomial in t of degree 0-2 (up to 27 float16)",
        parameters=COATED_PARAMETERS,
        max_degree=2,
        check=check_coefficients,
        evaluate=coated_conductor_model,
        glsl_file="cf_coated_conductor.glsl",
        hlsl_file="cf_coated_conductor.hlsl",
        glsl_function="cf_coated_conductor",
        preview_call="cf_coated_conductor_packed(NdotV, eta_i, eta_i_range, words)",
        material_template="material",
        split_sum=True,
        shader_variant="packed",
        collapsed_variant="collapsed",
        live_solver="polynomial",
    )
)
register_model_kind(
    ModelKind(
        name="rgb-conductor",
        code=1,
        description="exact Fresnel per channel of a fitted RGB n + i k under the coat, 6 float16",
        parameters=NK_PARAMETERS,
        max_degree=0,
        check=check_rgb_conductor_coefficients,
        evaluate=lambda cos_theta, eta_i, coefficients, eta_i_range: rgb_conductor_model(
            cos_theta, eta_i, coefficients
        ),
        glsl_file="cf_rgb_conductor.glsl",
        hlsl_file="cf_rgb_conductor.hlsl",
        glsl_function="cf_rgb_conductor",
        preview_call="cf_rgb_conductor_packed(NdotV, eta_i, uint[3](words[0], words[1], words[2]))",
        material_template="material_rgb",
        shader_variant="rgb_conductor",
        live_solver="exact-fresnel",
    )
)
