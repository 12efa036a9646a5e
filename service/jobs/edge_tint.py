"""
Fits of metals given by F0 and F82 tint
=======================================

``POST /api/v1/fits`` with ``{"name", "f0", "f82", "space"}``: a metal
described by two colours in air, linear, in ``space`` (``lin_rec709`` or
``acescg``). The colours are taken to linear ACEScg (the reflectance at 82
degrees, F82 tint times Schlick's there, is a colour; the tint is read back
from it), each ACEScg channel turned into n, k by
:func:`fitting.optics.edge_tint.nk_from_F0_F82`, and the metal is the
``rgb-conductor`` model of that index (exact Fresnel of the per-channel
relative index (n + i k) / eta_i), its n, k rounded to float16 as every
pack holds them. The record is of kind ``curves`` (a fit defined by its
model), id a content address of the request, saved as its own material;
the same request again answers the stored fit (200). Its provenance keeps
the colours, the space and, per channel, how far the F82 tint was out of
reach of any conductor (0 where it was reached).

-   :func:`fit_from_colours`: the record and whether it is new.
"""

from __future__ import annotations

import asyncio

import numpy as np

from fitting.exports.colour_space import working_to_ACEScg
from fitting.models.pack import PackedMaterial, material_to_json, to_float16
from fitting.models.rgb_conductor import MODEL_KIND as RGB_CONDUCTOR
from fitting.optics.edge_tint import F82_COS_THETA, nk_from_F0_F82

from ..store import FitRecord, Store
from .common import FIT_FORMAT_VERSION, checked_writable, content_address, fit_record

__all__ = ["fit_from_colours"]


def _schlick82(F0):
    return F0 + (1.0 - F0) * (1.0 - F82_COS_THETA) ** 5


def _to_ACEScg(F0, tint, space: str) -> tuple[np.ndarray, np.ndarray]:
    """F0 and F82 tint of ``space`` as ACEScg's (reflectances converted as colours), clipped to [0, 1]."""
    F0, tint = np.asarray(F0, dtype=np.float64), np.asarray(tint, dtype=np.float64)
    F0_a = np.clip(working_to_ACEScg(F0, space), 0.0, 1.0)
    R82_a = np.clip(working_to_ACEScg(tint * _schlick82(F0), space), 0.0, 1.0)
    return F0_a, np.clip(R82_a / _schlick82(F0_a), 0.0, 1.0)


def _make(store: Store, name: str, source: str, F0, tint, space: str, eta_i_range) -> tuple[FitRecord, bool]:
    fit_id = content_address("f0-f82/v1", FIT_FORMAT_VERSION, name, source, [float(v) for v in F0],
                             [float(v) for v in tint], space, [float(v) for v in eta_i_range])
    stored = store.get_fit(fit_id)
    if stored is not None:
        return stored, False
    checked_writable(store)
    F0_a, tint_a = _to_ACEScg(F0, tint, space)
    index = nk_from_F0_F82(F0_a, tint_a)
    packed = PackedMaterial(name, to_float16(np.stack([index.n, index.k])), tuple(eta_i_range), source,
                            model=RGB_CONDUCTOR)
    job = {"material": material_to_json(packed), "metrics": {}, "timings": {}, "convergence": {}}
    record = fit_record(fit_id, "curves", fit_id, name, source, job, objective="", provenance={
        "from_F0_F82": {"f0": list(map(float, F0)), "f82": list(map(float, tint)), "space": space,
                        "F82_error_ACEScg": index.F82_error.tolist()},
    })
    return store.put_fit(record), True


async def fit_from_colours(store: Store, request) -> tuple[FitRecord, bool]:
    """
    The stored fit of the metal a :class:`service.schemas.FitRequest` gives
    by ``f0``, ``f82``, ``space`` (with ``name``, default "metal", ``source``
    and ``eta_i_range``; see the module docstring), and whether it is new.
    """
    return await asyncio.to_thread(_make, store, (request.name or "metal").strip(), request.source,
                                   request.f0, request.f82, request.space, request.eta_i_range)
