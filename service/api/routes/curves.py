"""
Fits from edited RGB curves
===========================

-   ``POST /api/v1/fits/from-curves``: fit the model to RGB reflectance
    curves (linear ACEScg) at one or more eta_i, alone or as edits of a base
    (a built-in material, a stored fit or inline n, k); stored and
    downloadable like any fit (:func:`fitting.fits.curves.fit_curves`).
-   ``GET /api/v1/fits/{fit_id}/error-map``: Delta E 2000 of a stored fit
    over (angle, eta_i) against what it was fitted to, for the editor's heat
    map.

A curve fit belongs to the material named by its ``name`` (every refit of
"My gold" is kept, the latest is the material's current fit) and keeps its
base's n, k when there is one, so that its curves, preview comparison and
error map are against the measured data. The request is kept in the fit's
provenance, so the edited target can be rebuilt.
"""

from __future__ import annotations

import asyncio
import time
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from fastapi import APIRouter, HTTPException, Query, Response, status
from fastapi.concurrency import run_in_threadpool
from pydantic import BaseModel, ConfigDict, Field, model_validator

from fitting.colour.delta_e import delta_E_map
from fitting.domain import DEFAULT_ETA_I_RANGE, check_eta_i_range, cos_theta_from_angle
from fitting.fits.curves import CurveFitSettings, fit_curves
from fitting.fits.curves_base import (
    CurveBase,
    curve_base_from_coefficients,
    curve_base_from_nk,
    edited_target,
)
from fitting.fits.curves_input import (
    CURVE_MAX_COUNT,
    CURVE_MAX_SAMPLES,
    CURVE_MIN_SAMPLES,
    check_curves,
)
from fitting.models.kinds import model_ACEScg
from fitting.models.pack import material_from_json, material_to_json
from fitting.optics.library import library_material
from fitting.optics.nk import SpectralNK

from ...ids import content_id
from ...fitting_jobs import FIT_FORMAT_VERSION, check_finite, fit_record, measured_nk
from ...models import FIT_ID_PATTERN, ErrorBody, EtaI, FitPublic, LibraryName, NKData, Objective
from ...store import FitRecord, Store
from ..deps import ERROR_RESPONSES, FIT_ERROR_RESPONSES, RunnerDep, StoreDep, WriteAccess, fit_errors
from .fits import FitIdPath, fit_answer, stored_fit
from .targets import _target_of

router = APIRouter(prefix="/api/v1", tags=["curves"])

CURVES_FORMAT = "curves/v2"
"""Part of every curve fit's id: bump it when a change to fit_curves changes results."""
_DEFAULTS = CurveFitSettings()

CosTheta = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
Angle = Annotated[float, Field(ge=0.0, le=90.0, allow_inf_nan=False)]
Reflectance = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]


class CurveIn(BaseModel):
    """
    One RGB reflectance curve at coating index ``eta_i``: linear ACEScg in
    [0, 1] against cos theta in [0, 1] (or the angle in degrees, [0, 90]).
    """

    model_config = ConfigDict(extra="forbid")

    eta_i: EtaI
    cos_theta: list[CosTheta] | None = Field(None, min_length=CURVE_MIN_SAMPLES, max_length=CURVE_MAX_SAMPLES)
    angle_deg: list[Angle] | None = Field(None, min_length=CURVE_MIN_SAMPLES, max_length=CURVE_MAX_SAMPLES)
    rgb: list[tuple[Reflectance, Reflectance, Reflectance]] = Field(
        min_length=CURVE_MIN_SAMPLES, max_length=CURVE_MAX_SAMPLES,
        description="[R, G, B] per sample, linear ACEScg",
    )

    @model_validator(mode="after")
    def _check_samples(self) -> "CurveIn":
        if (self.cos_theta is None) == (self.angle_deg is None):
            raise ValueError("give exactly one of `cos_theta` or `angle_deg`")
        samples = self.cos_theta if self.cos_theta is not None else self.angle_deg
        if len(samples) != len(self.rgb):
            raise ValueError(
                f"`rgb` must hold one [R, G, B] per sample ({len(samples)}), got {len(self.rgb)}"
            )
        return self


class CurveBaseIn(BaseModel):
    """The material being edited: exactly one of a built-in name, a stored fit or n, k."""

    model_config = ConfigDict(extra="forbid")

    material: LibraryName | None = Field(None, description="A built-in conductor")
    fit: Annotated[str, Field(pattern=FIT_ID_PATTERN)] | None = Field(None, description="A stored fit's id")
    nk: NKData | None = Field(None, description="Measured n, k")

    @model_validator(mode="after")
    def _check_choice(self) -> "CurveBaseIn":
        given = [k for k in ("material", "fit", "nk") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError("`base` must give exactly one of `material`, `fit` or `nk`")
        return self


class CurveFitRequest(BaseModel):
    """
    Curves to fit, alone (``base`` null: the eta_i dependence is what the
    curves determine) or as edits of ``base`` (each curve replaces the base
    at its eta_i, the change fading over ``blend_width`` in eta_i).
    """

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [{
                "name": "warm gold",
                "base": {"material": "Au"},
                "curves": [{
                    "eta_i": 1.5,
                    "angle_deg": [0, 30, 60, 75, 90],
                    "rgb": [[0.9, 0.7, 0.35], [0.9, 0.7, 0.35], [0.88, 0.69, 0.36],
                            [0.85, 0.7, 0.45], [1, 1, 1]],
                }],
            }]
        },
    )

    name: str = Field("edited", min_length=1, max_length=200, pattern=r"\S",
                      description="The material's name; refits under one name are one material")
    base: CurveBaseIn | None = None
    eta_i_range: tuple[EtaI, EtaI] | None = Field(
        None, description="Domain [lo, hi]: default the base fit's, else [1, 2.5]"
    )
    curves: list[CurveIn] = Field(min_length=1, max_length=CURVE_MAX_COUNT)
    objective: Objective = _DEFAULTS.objective
    blend_width: float = Field(_DEFAULTS.blend_width, gt=0.0, le=3.0, allow_inf_nan=False)
    draft: bool = Field(False, description="Store the fit without saving it under `name` (the editor's "
                                           "refits while editing); the same request with false saves it")

    @model_validator(mode="after")
    def _check_range(self) -> "CurveFitRequest":
        if self.eta_i_range is not None and self.eta_i_range[0] > self.eta_i_range[1]:
            lo, hi = self.eta_i_range
            raise ValueError(f"`eta_i_range` must not be empty: lo {lo:g} > hi {hi:g}")
        return self


@dataclass(frozen=True)
class _BaseSpec:
    """What a worker needs to build the base: picklable plain data."""

    kind: Literal["nk", "model"]
    name: str
    source: str
    eta_i_range: tuple[float, float]
    library_material: str | None = None
    nk: tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]] | None = None
    coefficients: tuple | None = None

    def build(self) -> CurveBase:
        if self.kind == "model":
            return curve_base_from_coefficients(
                np.asarray(self.coefficients), self.eta_i_range, self.name, self.source
            )
        return curve_base_from_nk(self.spectral_nk(), self.eta_i_range)

    def spectral_nk(self) -> SpectralNK:
        if self.library_material is not None:
            return library_material(self.library_material)
        wavelength, n, k = (np.asarray(a, dtype=np.float64) for a in self.nk)
        return SpectralNK(wavelength, n, k, name=self.name, source=self.source)

    def key(self) -> str:
        arrays = b"" if self.nk is None else np.asarray(self.nk, dtype="<f8").tobytes()
        coefficients = b"" if self.coefficients is None else np.asarray(self.coefficients, dtype="<f8").tobytes()
        lo, hi = self.eta_i_range
        return content_id(self.kind, self.name, self.source, self.library_material or "", arrays,
                          coefficients, repr((float(lo), float(hi))))


def _curves_job(base: _BaseSpec | None, curves: list[dict], eta_i_range, name: str,
                objective: str, blend_width: float) -> dict[str, Any]:
    """Worker process: build (or reuse) the base grid, fit, score."""
    t0 = time.perf_counter()
    base_grid = None if base is None else base.build()
    t_base = time.perf_counter() - t0
    result = fit_curves(
        curves, base_grid, None if base is not None else eta_i_range, name,
        objective=objective, blend_width=blend_width,
    )
    metrics = result.metrics
    summary = result.summary()
    summary.pop("timings")
    return {
        "material": material_to_json(result.packed),
        "metrics": {
            "grid": f"{sum(len(c['rgb']) for c in curves)} samples on {len(curves)} curve(s)",
            "model_float16": {"delta_E_mean": metrics["delta_E_mean"], "delta_E_max": metrics["delta_E_max"]},
            "by_curve": metrics["by_curve"],
            "fitted_samples": metrics["samples"],
            **({"target": metrics["target"]} if "target" in metrics else {}),
        },
        "timings": {**result.timings, "base": t_base},
        "convergence": summary,
        "source": result.packed.source,
    }


def _base_spec(request: CurveFitRequest, store: Store) -> tuple[_BaseSpec | None, FitRecord | None]:
    """The base of a request and, for a stored-fit base, its record (404 if not stored)."""
    ref = request.base
    if ref is None:
        return None, None
    requested = None if request.eta_i_range is None else check_eta_i_range(request.eta_i_range)
    if ref.material is not None:
        return _BaseSpec("nk", ref.material, library_material(ref.material).source,
                         requested or DEFAULT_ETA_I_RANGE, library_material=ref.material), None
    if ref.nk is not None:
        data = ref.nk
        return _BaseSpec("nk", f"{request.name} base", "user n, k", requested or DEFAULT_ETA_I_RANGE,
                         nk=(tuple(data.wavelength_nm), tuple(data.n), tuple(data.k))), None
    record = stored_fit(store, ref.fit)
    packed = material_from_json(record.material)
    domain = packed.eta_i_range
    if requested is not None and requested != domain:
        raise ValueError(
            f"`eta_i_range` must be the base fit's domain [{domain[0]:g}, {domain[1]:g}] or "
            f"omitted, got [{requested[0]:g}, {requested[1]:g}]"
        )
    if record.kind == "curves":
        # An edited material: its edits live in its stored model, not in the
        # n, k it started from.
        spec = _BaseSpec("model", record.name, record.source, domain,
                         coefficients=packed.coefficients.astype(np.float64).tolist())
    elif record.library_material is not None:
        spec = _BaseSpec("nk", record.library_material, record.source, domain,
                         library_material=record.library_material)
    else:  # an n, k fit
        spec = _BaseSpec("nk", record.name, record.source, domain,
                         nk=(tuple(record.nk["wavelength_nm"]), tuple(record.nk["n"]), tuple(record.nk["k"])))
    return spec, record


def _curve_dicts(request: CurveFitRequest) -> list[dict]:
    out = []
    for curve in request.curves:
        item = {"eta_i": curve.eta_i, "rgb": [list(v) for v in curve.rgb]}
        if curve.cos_theta is not None:
            item["cos_theta"] = list(curve.cos_theta)
        else:
            item["angle_deg"] = list(curve.angle_deg)
        out.append(item)
    return out


@router.post(
    "/fits/from-curves", response_model=FitPublic, status_code=status.HTTP_201_CREATED,
    responses={
        status.HTTP_200_OK: {"model": FitPublic, "description": "Served from the store"},
        status.HTTP_201_CREATED: {"model": FitPublic, "description": "Fitted and saved"},
        status.HTTP_404_NOT_FOUND: {"model": ErrorBody, "description": "The base fit is not stored"},
        **FIT_ERROR_RESPONSES,
    },
    dependencies=[WriteAccess],
)
async def create_fit_from_curves(
    request: CurveFitRequest, store: StoreDep, runner: RunnerDep, response: Response,
) -> FitPublic:
    """
    Fit the model to edited RGB curves and save the fit under the
    material ``name``. The answer is like ``POST /fits``; ``metrics.model``
    is the mean and max Delta E 2000 of the float16 fit against the curves
    at their samples (``metrics.details.target``: against the whole edited
    target, with a base).
    """
    curves = _curve_dicts(request)
    with fit_errors():
        base, base_record = await run_in_threadpool(_base_spec, request, store)
        # Checked here, before any work is queued: names the place of a refusal.
        check_curves(curves)
        eta_i_range = check_eta_i_range(request.eta_i_range or DEFAULT_ETA_I_RANGE)
        fit_id = content_id(
            FIT_FORMAT_VERSION, CURVES_FORMAT, request.name.strip(), base.key() if base else "",
            repr(curves), repr(eta_i_range if base is None else base.eta_i_range),
            request.objective, repr(request.blend_width), repr(_DEFAULTS),
        )
        stored = await asyncio.to_thread(store.get_fit, fit_id)
        created = stored is None
        if stored is not None:
            # An earlier state saved again (undo, then save): it becomes the
            # material's latest.
            record = stored if request.draft else await asyncio.to_thread(store.put_fit, stored)
        else:
            # The measured data behind the edit (for the reference curves and
            # previews): the base's, or, for an edited base, the data it had.
            measured_library = base.library_material if base else None
            measured_nk = None if base is None or base.nk is None else {
                "wavelength_nm": list(base.nk[0]), "n": list(base.nk[1]), "k": list(base.nk[2]),
            }
            if base_record is not None and base_record.kind == "curves":
                measured_library, measured_nk = base_record.library_material, base_record.nk

            async def make() -> FitRecord:
                job = await runner.run(
                    _curves_job, base, curves, eta_i_range, request.name.strip(),
                    request.objective, request.blend_width,
                )
                check_finite("metrics", job["metrics"])
                name = request.name.strip()
                record = fit_record(
                    fit_id, "curves", content_id("edited material", name), name, job["source"],
                    job, request.objective,
                    library_material=measured_library, nk=measured_nk,
                    base_fit_id=base_record.id if base_record else None,
                    provenance={
                        "fit_format": FIT_FORMAT_VERSION, "curves_format": CURVES_FORMAT,
                        "request": request.model_dump(mode="json", exclude={"base", "draft"}),
                        "base": None if base is None else {
                            "kind": base.kind, "name": base.name, "eta_i_range": list(base.eta_i_range),
                            "library_material": base.library_material,
                            "coefficients": base.coefficients,
                        },
                        "settings": {k: getattr(_DEFAULTS, k) for k in _DEFAULTS.__dataclass_fields__},
                    },
                )
                return await asyncio.to_thread(store.put_fit, record, not request.draft)

            record = await runner.once(fit_id, make)
            if not request.draft:
                # The fit was shared with a draft request in flight: saved now.
                latest = await asyncio.to_thread(store.latest_fit, record.material_id)
                if latest is None or latest.id != record.id:
                    record = await asyncio.to_thread(store.put_fit, record)
    return fit_answer(record, created, response)


class ErrorMap(BaseModel):
    """Delta E 2000 of a fit's float16 model over (eta_i, angle) against its target."""

    fit_id: str
    against: Literal["reference", "edited target", "curves"]
    theta_deg: list[float]
    eta_i: list[float]
    delta_E: list[list[float]] = Field(description="[eta_i row][angle column]")
    delta_E_mean: float
    delta_E_max: float


def _error_map(record: FitRecord, angles: int, rows: int) -> ErrorMap:
    packed = material_from_json(record.material)
    lo, hi = packed.eta_i_range
    theta = np.linspace(0.0, 90.0, angles)
    mu = cos_theta_from_angle(theta)
    eta = np.linspace(lo, hi, rows) if hi > lo else np.array([lo])
    eta, target, against = _target_of(record, mu, eta)
    E, M = np.meshgrid(eta, mu, indexing="ij")
    model = model_ACEScg(packed.model, M, E, packed.coefficients, packed.eta_i_range)
    dE = delta_E_map(target, model)
    return ErrorMap(
        fit_id=record.id, against=against, theta_deg=theta.tolist(), eta_i=eta.tolist(),
        delta_E=np.round(dE, 4).tolist(), delta_E_mean=float(dE.mean()), delta_E_max=float(dE.max()),
    )


@router.get(
    "/fits/{fit_id}/error-map", response_model=ErrorMap,
    responses={**ERROR_RESPONSES, status.HTTP_404_NOT_FOUND: {"model": ErrorBody}},
)
async def get_error_map(
    fit_id: FitIdPath, store: StoreDep,
    angles: Annotated[int, Query(ge=2, le=181, description="Angles evenly from 0 to 90 degrees")] = 46,
    rows: Annotated[int, Query(ge=1, le=101, description="eta_i values evenly over the domain")] = 31,
) -> ErrorMap:
    """
    Delta E 2000 of the fit's float16 model against what it was fitted to:
    the spectral reference (5 nm) of its n, k, or for a curve fit the edited
    target (with a base) or the curves themselves (rows at their eta_i).
    """
    record = await run_in_threadpool(stored_fit, store, fit_id)
    try:
        return await run_in_threadpool(_error_map, record, angles, rows)
    except ValueError as error:
        raise HTTPException(status.HTTP_422_UNPROCESSABLE_CONTENT, str(error)) from None
