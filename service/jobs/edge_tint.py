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
-   :func:`colour_curves`: the same metal's curves at given coating
    indices, the colours seen in air or from under a coat (the editor's
    colour controls; nothing stored).
"""

from __future__ import annotations

import asyncio

import numpy as np

from fitting.domain import cos_theta_from_angle
from fitting.exports.colour_space import working_to_ACEScg
from fitting.models.pack import PackedMaterial, material_to_json, to_float16
from fitting.models.rgb_conductor import MODEL_KIND as RGB_CONDUCTOR
from fitting.models.rgb_conductor import rgb_fresnel_conductor
from fitting.optics.edge_tint import F82_COS_THETA, nk_from_F0_F82

from ..store import FitRecord, Store
from .common import FIT_FORMAT_VERSION, checked_writable, content_address, fit_record

__all__ = ["fit_from_colours", "colour_curves"]


def _schlick82(F0):
    return F0 + (1.0 - F0) * (1.0 - F82_COS_THETA) ** 5


def _to_ACEScg(F0, tint, space: str) -> tuple[np.ndarray, np.ndarray]:
    """F0 and F82 tint of ``space`` as ACEScg's (reflectances converted as colours), clipped to [0, 1]."""
    F0, tint = np.asarray(F0, dtype=np.float64), np.asarray(tint, dtype=np.float64)
    F0_a = np.clip(working_to_ACEScg(F0, space), 0.0, 1.0)
    R82_a = np.clip(working_to_ACEScg(tint * _schlick82(F0), space), 0.0, 1.0)
    return F0_a, np.clip(R82_a / _schlick82(F0_a), 0.0, 1.0)


def _make(store: Store, name: str, source: str, F0, tint, space: str, eta_i_range) -> tuple[FitRecord, bool]:
    fit_id = content_address(
        "f0-f82/v1",
        FIT_FORMAT_VERSION,
        name,
        source,
        [float(v) for v in F0],
        [float(v) for v in tint],
        space,
        [float(v) for v in eta_i_range],
    )
    stored = store.get_fit(fit_id)
    if stored is not None:
        return stored, False
    checked_writable(store)
    F0_a, tint_a = _to_ACEScg(F0, tint, space)
    index = nk_from_F0_F82(F0_a, tint_a)
    packed = PackedMaterial(
        name, to_float16(np.stack([index.n, index.k])), tuple(eta_i_range), source, model=RGB_CONDUCTOR
    )
    job = {"material": material_to_json(packed), "metrics": {}, "timings": {}, "convergence": {}}
    record = fit_record(
        fit_id,
        "curves",
        fit_id,
        name,
        source,
        job,
        objective="",
        provenance={
            "from_F0_F82": {
                "f0": list(map(float, F0)),
                "f82": list(map(float, tint)),
                "space": space,
                "F82_error_ACEScg": index.F82_error.tolist(),
            },
        },
    )
    return store.put_fit(record), True


async def fit_from_colours(store: Store, request) -> tuple[FitRecord, bool]:
    """
    The stored fit of the metal a :class:`service.schemas.FitRequest` gives
    by ``f0``, ``f82``, ``space`` (with ``name``, default "metal", ``source``
    and ``eta_i_range``; see the module docstring), and whether it is new.
    """
    return await asyncio.to_thread(
        _make,
        store,
        (request.name or "metal").strip(),
        request.source,
        request.f0,
        request.f82,
        request.space,
        request.eta_i_range,
    )


def colour_curves(F0, tint, space: str, seen_at: float, eta_i, samples: int) -> dict:
    """
    The reflectance curves (linear ACEScg, ``samples`` angles evenly from 0
    to 90 degrees) at each coating index of ``eta_i`` of the metal whose F0
    and F82 tint (linear colours of ``space``) are seen from a medium of
    index ``seen_at``: per ACEScg channel the index of
    :func:`fitting.optics.edge_tint.nk_from_F0_F82` is the relative index
    (n + i k) / seen_at, so the metal's own index is that times ``seen_at``
    (1: the colours are the metal in air). The curve at ``seen_at`` then
    starts at F0; the others are the same metal under other coats.
    """
    F0_a, tint_a = _to_ACEScg(F0, tint, space)
    index = nk_from_F0_F82(F0_a, tint_a)
    n, k = index.n * float(seen_at), index.k * float(seen_at)
    theta = np.linspace(0.0, 90.0, int(samples))
    mu = cos_theta_from_angle(theta)
    curves = [
        {"eta_i": float(eta), "rgb": np.clip(rgb_fresnel_conductor(mu, float(eta), n, k), 0.0, 1.0).tolist()}
        for eta in eta_i
    ]
    return {
        "theta_deg": theta.tolist(),
        "curves": curves,
        "n": n.tolist(),
        "k": k.tolist(),
        "reachable": index.reachable.tolist(),
        "F82_error": index.F82_error.tolist(),
    }
