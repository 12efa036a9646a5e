"""
Model kinds of a batch
======================

A batch fits the kinds of the one registry (:data:`fitting.models.kinds.MODEL_KINDS`,
each fitted by its :class:`~fitting.fits.pipeline.FitKind` of
:data:`fitting.fits.kinds.FIT_KINDS`): a kind registered there is a
``--model`` choice, with no registration here. Each kind fits one page's
*n*, *k* and returns its pack record (as the JSON view a journal stores) and
its linear ACEScg evaluation, which the batch scores against the spectral
reference.

-   :class:`KindFit`: what a kind's fit of a page returns.
-   :func:`batch_kinds`: the kinds a batch can fit; :data:`DEFAULT_MODEL_KIND`.
-   :func:`fit_kind_page`: one kind's fit of one page's *n*, *k*.
-   :func:`decode_material`: a stored view back to the record the pack encoder takes.
-   :func:`check_model_kinds`: the requested kinds, checked.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..fits.kinds import FIT_KINDS, fit_model
from ..models.kinds import DEFAULT_MODEL, MODEL_KINDS, model_ACEScg
from ..models.pack import PackedMaterial, material_from_json, material_to_json
from ..optics.nk import SpectralNK

__all__ = [
    "DEFAULT_MODEL_KIND",
    "KindFit",
    "batch_kinds",
    "check_model_kinds",
    "decode_material",
    "fit_kind_page",
]

DEFAULT_MODEL_KIND = DEFAULT_MODEL


@dataclass(frozen=True)
class KindFit:
    """
    One kind's fit of one page.

    ``material`` is the pack record's JSON view (exact, so a journal can
    store it and :func:`decode_material` rebuild the record);
    ``model_ACEScg(cos_theta, eta_i)`` evaluates the fitted model as shipped
    (linear ACEScg, shape ``broadcast.shape + (3,)``).
    """

    material: dict[str, Any]
    model_ACEScg: Callable[[np.ndarray, np.ndarray], np.ndarray]


def batch_kinds() -> tuple[str, ...]:
    """The registered kinds that have a fit, in registry order."""
    return tuple(name for name in MODEL_KINDS if name in FIT_KINDS)


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
    known = batch_kinds()
    for name in names:
        if name not in known:
            raise ValueError(f"`model` must be one of {', '.join(sorted(known))}, got {name!r}")
    return names


def fit_kind_page(kind: str, nk: SpectralNK, eta_i_range) -> KindFit:
    """Kind ``kind`` fitted to ``nk`` (:func:`fitting.fits.kinds.fit_model`), its record and its model as shipped."""
    packed = fit_model(nk, eta_i_range, kind).packed
    C = packed.coefficients.astype(np.float64)
    domain = packed.eta_i_range
    return KindFit(
        material=material_to_json(packed),
        model_ACEScg=lambda M, E: model_ACEScg(kind, M, E, C, domain),
    )


def decode_material(view: dict[str, Any]) -> PackedMaterial:
    """The record of a stored view (:func:`fitting.models.pack.material_from_json`, any kind)."""
    return material_from_json(view)
