"""
Fits from edited RGB curves
===========================

-   :func:`prepare_curve_fit`: a validated :class:`CurveFit` (the base
    resolved, the curves checked, the id computed), before any work is queued.
-   :func:`fit_from_curves`: the stored fit of a :class:`CurveFit`, else
    fitted in the pool and saved; ``(record, created)``.
-   :func:`error_map`: Delta E 2000 of a stored fit over (eta_i, angle)
    against what it was fitted to.

A curve fit belongs to the material named by its ``name`` and keeps its
base's n, k when there is one (for an edited base: the n, k it had), so that
its curves, preview comparison and error map are against the measured data.
The request is kept in the fit's provenance, so the edited target can be
rebuilt. The base's domain is stored as float32 (the pack's type); a request
naming the base's domain, or a curve at its bound, is compared after the
same rounding.
"""

from __future__ import annotations

import asyncio
import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from fitting.domain import DEFAULT_ETA_I_RANGE, check_eta_i_range
from fitting.fits.curves import LIVE_SETTINGS, CurveFitSettings, fit_curves
from fitting.fits.curves_input import check_curves
from fitting.models.kinds import DEFAULT_MODEL
from fitting.models.pack import material_from_json, material_to_json
from fitting.optics.catalogue import catalogue_material

from ..runtime import FitRunner
from ..store import FitRecord, Store
from .common import (
    FIT_FORMAT_VERSION,
    check_finite,
    checked_version,
    checked_writable,
    content_address,
    draft_nk_reference,
    fit_record,
    stored_fit,
    with_measured_nk,
)
from .curve_bases import BaseSpec
from .curve_targets import error_map, snap_to_domain, target_at
from .materials import resolve_material

__all__ = ["CURVES_FORMAT", "CurveFit", "prepare_curve_fit", "fit_from_curves", "error_map", "target_at"]

CURVES_FORMAT = "curves/v5"
"""Part of every curve fit's id: bump it when a change to fit_curves changes results."""
DEFAULTS = CurveFitSettings()
DEFAULT_DOMAIN = DEFAULT_ETA_I_RANGE


@dataclass(frozen=True)
class CurveFit:
    """A validated curve fit: its base, curves, domain, id and provenance."""

    name: str
    base: BaseSpec | None
    base_record: FitRecord | None
    curves: list[dict]
    eta_i_range: tuple[float, float]
    objective: str
    blend_width: float
    request: dict[str, Any]
    fit_id: str
    draft: bool = False
    model: str = DEFAULT_MODEL
    live: bool = False
    start: tuple | None = None  # with live: the coefficients the solve starts from
    material_id: str = ""  # the material it is saved under (resolve_material)


def _float32_equal(a: tuple[float, float], b: tuple[float, float]) -> bool:
    return bool(np.all(np.float32(a) == np.float32(b)))


def _base_spec(
    store: Store, name: str, material: str | None, fit: str | None, nk: tuple | None, requested
) -> tuple[BaseSpec | None, FitRecord | None]:
    if material is not None:
        return BaseSpec(
            "nk", material, catalogue_material(material).source, requested or DEFAULT_DOMAIN, library_material=material
        ), None
    if nk is not None:
        return BaseSpec("nk", f"{name} base", "user n, k", requested or DEFAULT_DOMAIN, nk=nk), None
    if fit is None:
        return None, None
    record = stored_fit(store, fit, "base.fit")
    domain = material_from_json(record.material).eta_i_range
    if requested is not None and not _float32_equal(requested, domain):
        raise ValueError(
            f"`eta_i_range` must be the base fit's domain [{domain[0]:g}, {domain[1]:g}] or "
            f"omitted, got [{requested[0]:g}, {requested[1]:g}]"
        )
    if record.kind == "curves":
        # An edited material: its edits live in its stored model, not in the
        # n, k it started from.
        packed = material_from_json(record.material)
        spec = BaseSpec(
            "model",
            record.name,
            record.source,
            domain,
            coefficients=packed.coefficients.astype(np.float64).tolist(),
            model=packed.model,
        )
    elif record.library_material is not None:
        spec = BaseSpec("nk", record.library_material, record.source, domain, library_material=record.library_material)
    else:  # an n, k fit
        spec = BaseSpec(
            "nk",
            record.name,
            record.source,
            domain,
            nk=(tuple(record.nk["wavelength_nm"]), tuple(record.nk["n"]), tuple(record.nk["k"])),
        )
    return spec, record


def prepare_curve_fit(
    store: Store,
    name: str,
    curves: list[dict],
    *,
    base_material: str | None = None,
    base_fit: str | None = None,
    base_nk: tuple | None = None,
    eta_i_range=None,
    objective: str = DEFAULTS.objective,
    blend_width: float = DEFAULTS.blend_width,
    request: dict[str, Any] | None = None,
    draft: bool = False,
    model: str = DEFAULT_MODEL,
    live: bool = False,
    start_fit: str | None = None,
    material_id: str | None = None,
) -> CurveFit:
    """
    Resolve the base (``LookupError`` for a base fit not stored), check the
    curves and the domain (``ValueError``), and compute the id. A ``live``
    refit (a draft, :data:`fitting.fits.curves.LIVE_SETTINGS`) starts from
    the coefficients of the stored ``start_fit`` when given (of the same
    kind and domain). Runs in a thread (it reads the store).
    """
    if live and not draft:
        raise ValueError("`live` refits are drafts: set `draft` to true (a live refit is never saved)")
    if start_fit is not None and not live:
        raise ValueError("`start_fit` is for `live` refits only")
    name = name.strip()
    requested = None if eta_i_range is None else check_eta_i_range(eta_i_range)
    base, base_record = _base_spec(store, name, base_material, base_fit, base_nk, requested)
    if base is not None:
        curves = snap_to_domain(curves, base.eta_i_range)
    check_curves(curves)
    domain = base.eta_i_range if base is not None else check_eta_i_range(requested or DEFAULT_DOMAIN)
    start = None if start_fit is None else _start_coefficients(store, start_fit, domain, model, base, curves)
    material_id = resolve_material(store, name, material_id, saving=not draft)
    fit_id = content_address(
        FIT_FORMAT_VERSION,
        CURVES_FORMAT,
        name,
        None if base is None else base.key(),
        curves,
        list(domain),
        objective,
        blend_width,
        repr(DEFAULTS),
        # The default kind adds nothing, so coated-conductor ids stay as they were.
        *(() if model == DEFAULT_MODEL else (model,)),
        # Nor does a full refit.
        *(() if not live else ("live", repr(LIVE_SETTINGS), None if start is None else np.ravel(start))),
        # Nor does the material a name gives (a record names its material once).
        *(() if material_id == content_address("edited material", name) else ("material", material_id)),
    )
    return CurveFit(
        name,
        base,
        base_record,
        curves,
        domain,
        objective,
        blend_width,
        request or {},
        fit_id,
        draft,
        model,
        live,
        None if start is None else tuple(np.ravel(start).tolist()),
        material_id,
    )


def _start_coefficients(store: Store, start_fit: str, domain, model: str, base, curves) -> np.ndarray | None:
    """The float16 coefficients of ``start_fit`` as float64 (None for the rgb-conductor kind,
    whose solve has no warm start); ValueError when its kind, domain or degree differ."""
    packed = material_from_json(stored_fit(store, start_fit, "start_fit").material)
    if packed.model != model:
        raise ValueError(f"`start_fit` must be a fit of the model kind {model!r}, got {packed.model!r}")
    if not _float32_equal(packed.eta_i_range, domain):
        lo, hi = packed.eta_i_range
        raise ValueError(
            f"`start_fit` must have the refit's domain [{domain[0]:g}, {domain[1]:g}], got [{lo:g}, {hi:g}]"
        )
    if model != DEFAULT_MODEL:
        return None
    coefficients = packed.coefficients.astype(np.float64)
    if base is None:
        degree = 0 if domain[1] <= domain[0] else min(2, len({float(c["eta_i"]) for c in curves}) - 1)
    else:
        degree = 0 if domain[1] <= domain[0] else 2
    if coefficients.shape != (3, 3, degree + 1):
        raise ValueError(
            f"`start_fit` must have degree {degree} in eta_i as the refit has, got {coefficients.shape[2] - 1}"
        )
    return coefficients


def _curves_job(
    base: BaseSpec | None,
    curves: list[dict],
    eta_i_range,
    name: str,
    objective: str,
    blend_width: float,
    model: str = DEFAULT_MODEL,
    live: bool = False,
    start: tuple | None = None,
) -> dict[str, Any]:
    """Worker process: build (or reuse) the base grid, fit, score."""
    t0 = time.perf_counter()
    base_grid = None if base is None else base.build()
    t_base = time.perf_counter() - t0
    result = fit_curves(
        curves,
        base_grid,
        None if base is not None else eta_i_range,
        name,
        settings=LIVE_SETTINGS if live else DEFAULTS,
        objective=objective,
        blend_width=blend_width,
        model=model,
        start=None if start is None else np.reshape(start, (3, 3, -1)),
    )
    metrics = result.metrics
    summary = result.summary()
    summary.pop("timings")
    return {
        "material": material_to_json(result.packed),
        # The core's metrics JSON as fit_curves made it (its ``figure`` the
        # one figure), with the keys every fit's record has: ``grid`` and
        # ``model_float16`` (the figure at the curves' own samples).
        "metrics": {
            **metrics,
            "grid": f"{sum(len(c['rgb']) for c in curves)} samples on {len(curves)} curve(s)",
            "model_float16": {
                key: metrics[key] for key in ("against", "delta_E_mean", "delta_E_max", "max_at") if key in metrics
            },
        },
        "timings": {**result.timings, "base": t_base},
        "convergence": summary,
        "source": result.packed.source,
    }


async def fit_from_curves(
    fit: CurveFit, store: Store, runner: FitRunner, expected_version: int | None = None
) -> tuple[FitRecord, bool, bool]:
    """
    The stored fit of ``fit`` (an earlier state saved again becomes the
    latest), else fitted and saved; a draft (the editor's refits while
    editing) is stored but not saved under its material until the same
    request comes without ``draft``. ``expected_version``: the save is
    refused (:class:`service.store.StoreConflict`, 409) unless the material
    is at that version, under the save's name and not in the bin. Returns
    (record, fitted now, the save took the material out of the bin).
    """
    material_id = fit.material_id

    def stored_or_writable() -> tuple[FitRecord | None, bool]:
        # One trip to a thread for both (a live refit is a round trip per drag step).
        stored = with_measured_nk(store, store.get_fit(fit.fit_id))
        if stored is None:
            checked_writable(store)
        in_bin = False if fit.draft else checked_version(store, material_id, fit.name, expected_version)
        return stored, in_bin

    def put(record: FitRecord, save: bool = True, expected: int | None = None, nk=None) -> FitRecord:
        return with_measured_nk(store, store.put_fit(record, save, expected, nk))

    stored, in_bin = await asyncio.to_thread(stored_or_writable)
    if stored is not None:
        if fit.draft:
            return stored, False, False
        return await asyncio.to_thread(put, stored, True, expected_version), False, in_bin
    base, base_record = fit.base, fit.base_record
    # The measured data behind the edit (for the reference curves and
    # previews): the base's, or, for an edited base, the data it had.
    measured_library = base.library_material if base else None
    measured = (
        None
        if base is None or base.nk is None
        else {
            "wavelength_nm": list(base.nk[0]),
            "n": list(base.nk[1]),
            "k": list(base.nk[2]),
        }
    )
    if base_record is not None and base_record.kind == "curves":
        measured_library, measured = base_record.library_material, base_record.nk
    # A draft refers to its n, k, never holds a copy (~0.5 MB a step for 20,000 samples).
    own_nk, nk_of, nk_id, draft_nk = await asyncio.to_thread(draft_nk_reference, fit.draft, base_record, measured)

    settings = LIVE_SETTINGS if fit.live else DEFAULTS
    made_here = []  # set when this request's own job ran (and, unless a draft, saved)

    async def make() -> FitRecord:
        made_here.append(True)
        job = await runner.run(
            _curves_job,
            base,
            fit.curves,
            fit.eta_i_range,
            fit.name,
            fit.objective,
            fit.blend_width,
            fit.model,
            fit.live,
            fit.start,
            cost_s=0.03 if fit.live else 0.5,
        )  # its turn: live steps first
        check_finite("metrics", job["metrics"])
        record = fit_record(
            fit.fit_id,
            "curves",
            material_id,
            fit.name,
            job["source"],
            job,
            fit.objective,
            library_material=measured_library,
            nk=own_nk,
            nk_id=nk_id,
            base_fit_id=base_record.id if base_record else None,
            provenance={
                "fit_format": FIT_FORMAT_VERSION,
                "curves_format": CURVES_FORMAT,
                "request": fit.request,
                "base": None if base is None else base.provenance(),
                "settings": {k: getattr(settings, k) for k in settings.__dataclass_fields__},
                **({"live": {"start": fit.start}} if fit.live else {}),
                **({"nk_of": nk_of} if nk_of is not None else {}),
            },
        )
        stored = await asyncio.to_thread(store.put_fit, record, not fit.draft, expected_version, draft_nk)
        # Its n, k is known here (a read back would parse it again: 0.6 MB of JSON at 20,000 samples).
        return stored if stored.nk is not None or measured is None else replace(stored, nk=measured)

    record = await runner.once(fit.fit_id, make)
    if not fit.draft and not made_here:
        # Another request's flight made it (a draft's, or the same save's): saved now,
        # once. (Asking whether it is the latest would race with other saves.)
        record = await asyncio.to_thread(put, record, True, expected_version)
    return record, True, in_bin
