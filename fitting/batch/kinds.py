"""
Model kinds of a batch
======================

The registry of model kinds a batch can fit, keyed by the name given to
``--model``; each kind fits one page's *n*, *k* and returns its pack record
(as the JSON view a journal stores) and its linear ACEScg evaluation, which
the batch scores against the spectral reference.

-   :class:`ModelKind`: a kind's name, description and fit.
-   :class:`KindFit`: what a kind's fit returns.
-   :data:`MODEL_KINDS`: the registered kinds; :data:`DEFAULT_MODEL_KIND`.
-   :func:`register_model_kind`, :func:`check_model_kinds`.

The kinds are those of :data:`fitting.models.kinds.MODEL_KINDS`
(``coated-conductor``, ``rgb-conductor``); a new kind plugs in with one
:func:`register_model_kind` call below, giving a ``fit(nk, eta_i_range) ->
KindFit``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..fits.material import fit_material
from ..fits.rgb_conductor import fit_rgb_conductor
from ..models.kinds import DEFAULT_MODEL, model_ACEScg
from ..models.pack import PackedMaterial, material_from_json, material_to_json
from ..optics.nk import SpectralNK

__all__ = [
    "DEFAULT_MODEL_KIND",
    "KindFit",
    "MODEL_KINDS",
    "ModelKind",
    "check_model_kinds",
    "register_model_kind",
]


@dataclass(frozen=True)
class KindFit:
    """
    One kind's fit of one page.

    ``material`` is the pack record's JSON view (exact, so a journal can
    store it and :attr:`ModelKind.decode` rebuild the record);
    ``model_ACEScg(cos_theta, eta_i)`` evaluates the fitted model as shipped
    (linear ACEScg, shape ``broadcast.shape + (3,)``).
    """

    material: dict[str, Any]
    model_ACEScg: Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class ModelKind:
    """
    A model kind: ``fit(nk, eta_i_range) -> KindFit`` and ``decode(view)``,
    the inverse of the stored view, giving the record the pack encoder takes.
    """

    name: str
    description: str
    fit: Callable[[SpectralNK, tuple[float, float]], KindFit]
    decode: Callable[[dict[str, Any]], PackedMaterial]


MODEL_KINDS: dict[str, ModelKind] = {}
DEFAULT_MODEL_KIND = DEFAULT_MODEL


def register_model_kind(kind: ModelKind) -> ModelKind:
    """Add ``kind`` to :data:`MODEL_KINDS` (a name is registered once)."""
    if kind.name in MODEL_KINDS:
        raise ValueError(f"model kind {kind.name!r} is already registered")
    MODEL_KINDS[kind.name] = kind
    return kind


def check_model_kinds(kinds) -> tuple[str, ...]:
    """
    The requested kinds, each known, without repeats, in the order given.

    Raises
    ------
    ValueError
        For an empty list or an unknown kind.
    """
    names = tuple(dict.fromkeys(kinds))
    if not names:
        raise ValueError("`model` must name at least one model kind")
    for name in names:
        if name not in MODEL_KINDS:
            raise ValueError(
                f"`model` must be one of {', '.join(sorted(MODEL_KINDS))}, got {name!r}"
            )
    return names


def _kind_fit(packed: PackedMaterial) -> KindFit:
    """The record of ``packed`` and its model evaluated from the float16 coefficients as shipped."""
    C = packed.coefficients.astype(np.float64)
    kind, domain = packed.model, packed.eta_i_range
    return KindFit(
        material=material_to_json(packed),
        model_ACEScg=lambda M, E: model_ACEScg(kind, M, E, C, domain),
    )


register_model_kind(ModelKind(
    name="coated-conductor",
    description="Vernooij (2024) coated-conductor model, 27 float16 coefficients",
    fit=lambda nk, eta_i_range: _kind_fit(fit_material(nk, eta_i_range).packed),
    decode=material_from_json,
))
register_model_kind(ModelKind(
    name="rgb-conductor",
    description="exact Fresnel per channel of a fitted RGB n + i k, 6 float16 coefficients",
    fit=lambda nk, eta_i_range: _kind_fit(fit_rgb_conductor(nk, eta_i_range).packed),
    decode=material_from_json,
))
