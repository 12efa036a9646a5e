"""
Fits
====

-   ``POST /api/v1/fits``: fit a built-in material or inline n, k (JSON).
-   ``POST /api/v1/fits/upload``: fit an uploaded n, k file (CSV, JSON or
    refractiveindex.info YAML), multipart.
-   ``GET /api/v1/fits/{fit_id}``: a stored fit.
-   ``GET /api/v1/fits/{fit_id}/pack``: its download (binary, json, glsl,
    hlsl) or an export for one coating index (mtlx, openpbr, blender, gltf).
-   ``GET /api/v1/fits/{fit_id}/curves``: reference, model and baseline RGB
    against the angle, for plotting.

Fits are content addressed: the same input gives the same id and is served
from the store (200) without refitting; a new fit answers 201.
"""

from __future__ import annotations

from pathlib import PurePath
from typing import Annotated, Literal

import numpy as np
from fastapi import APIRouter, File, Form, HTTPException, Path, Query, Response, UploadFile, status
from fastapi.concurrency import run_in_threadpool

from fitting.colour.reference import reference_ACEScg
from fitting.domain import DEFAULT_ETA_I_RANGE, ETA_I_MAX, ETA_I_MIN, cos_theta_from_angle
from fitting.fits.settings import DEFAULT_OBJECTIVE
from fitting.models.baselines import baseline_inputs, lazanyi_adjusted
from fitting.models.kinds import model_ACEScg
from fitting.models.pack import material_from_json
from fitting.optics.nk import SpectralNK
from fitting.optics.readers import FORMATS, read_nk

from ...downloads import (
    EXPORT_MEDIA_TYPES,
    PACK_MEDIA_TYPES,
    download_name,
    render_export,
    render_pack,
)
from ...fitting_jobs import NKFitSpec, fit_nk, measured_nk
from ...models import (
    API_PREFIX,
    FIT_ID_PATTERN,
    MAX_NK_SAMPLES,
    CurvesPublic,
    ErrorBody,
    FitPublic,
    FitRequest,
    PACK_FORMATS,
    Objective,
    fit_public,
)
from ...store import FitRecord, Store
from .targets import target_at
from ..deps import (
    ERROR_RESPONSES,
    FIT_ERROR_RESPONSES,
    RunnerDep,
    SettingsDep,
    StoreDep,
    WriteAccess,
    fit_errors,
)

router = APIRouter(prefix=f"{API_PREFIX}/fits", tags=["fits"])

FitIdPath = Annotated[str, Path(pattern=FIT_ID_PATTERN, description="32 lowercase hex digits")]
NOT_FOUND = {status.HTTP_404_NOT_FOUND: {"model": ErrorBody, "description": "No fit with this id"}}
PACK_CONTENT = {
    "application/octet-stream": {"schema": {"type": "string", "format": "binary"}},
    "application/json": {"schema": {"type": "object"}},
    "text/plain": {"schema": {"type": "string"}},
    "application/xml": {"schema": {"type": "string"}},
    "text/x-python": {"schema": {"type": "string"}},
    "model/gltf+json": {"schema": {"type": "object"}},
}
DownloadFormat = Literal[(*PACK_FORMATS, *EXPORT_MEDIA_TYPES)]  # type: ignore[valid-type]
CREATED = {
    status.HTTP_200_OK: {"model": FitPublic, "description": "Served from the store"},
    status.HTTP_201_CREATED: {"model": FitPublic, "description": "Fitted and saved"},
}


def stored_fit(store: Store, fit_id: str) -> FitRecord:
    """The record of ``fit_id`` or 404."""
    record = store.get_fit(fit_id)
    if record is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, f"`fit_id` {fit_id} is not a stored fit")
    return record


def fit_answer(record: FitRecord, created: bool, response: Response) -> FitPublic:
    """A fit's answer: 201 when just fitted, 200 from the store; Location of the fit."""
    response.status_code = status.HTTP_201_CREATED if created else status.HTTP_200_OK
    response.headers["Location"] = f"{API_PREFIX}/fits/{record.id}"
    return fit_public(record)


async def _answer(spec: NKFitSpec, store: Store, runner, response: Response) -> FitPublic:
    with fit_errors():
        record, created = await fit_nk(spec, store, runner)
    return fit_answer(record, created, response)


@router.post(
    "", response_model=FitPublic, status_code=status.HTTP_201_CREATED,
    responses={**CREATED, **FIT_ERROR_RESPONSES}, dependencies=[WriteAccess],
)
async def create_fit(
    request: FitRequest, store: StoreDep, runner: RunnerDep, settings: SettingsDep,
    response: Response,
) -> FitPublic:
    """
    Fit a built-in material (``{"material": "Au"}``) or inline n, k
    (``{"name": ..., "nk": {"wavelength_nm", "n", "k"}}``) over
    ``eta_i_range``; the answer carries the float16 coefficients, Delta E
    2000 of the model and of adjusted Lazanyi, and timings.
    """
    if request.material is not None:
        spec = NKFitSpec(
            kind="library", name=request.material, source="",
            eta_i_range=request.eta_i_range, objective=request.objective,
            library_material=request.material, metrics_samples=settings.metrics_samples,
            model=request.model,
        )
    else:
        spec = NKFitSpec(
            kind="nk", name=(request.name or "uploaded").strip(), source=request.source,
            eta_i_range=request.eta_i_range, objective=request.objective,
            wavelength_nm=tuple(request.nk.wavelength_nm), n=tuple(request.nk.n),
            k=tuple(request.nk.k), metrics_samples=settings.metrics_samples,
            model=request.model,
        )
    return await _answer(spec, store, runner, response)


@router.post(
    "/upload", response_model=FitPublic, status_code=status.HTTP_201_CREATED,
    responses={**CREATED, **FIT_ERROR_RESPONSES}, dependencies=[WriteAccess],
)
async def upload_fit(
    file: Annotated[UploadFile, File(description="n, k as CSV, JSON or refractiveindex.info YAML")],
    store: StoreDep, runner: RunnerDep, settings: SettingsDep, response: Response,
    format: Annotated[
        str | None,
        Form(pattern=r"^(csv|json|yaml|yml)$", description="Default: from the file name"),
    ] = None,
    name: Annotated[str | None, Form(min_length=1, max_length=200, pattern=r"\S")] = None,
    eta_i_min: Annotated[float, Form(ge=ETA_I_MIN, le=ETA_I_MAX, allow_inf_nan=False)] = DEFAULT_ETA_I_RANGE[0],
    eta_i_max: Annotated[float, Form(ge=ETA_I_MIN, le=ETA_I_MAX, allow_inf_nan=False)] = DEFAULT_ETA_I_RANGE[1],
    objective: Annotated[Objective, Form()] = DEFAULT_OBJECTIVE,
) -> FitPublic:
    """
    Fit an uploaded n, k file (size limit: COATED_MAX_UPLOAD_BYTES). The
    file is parsed, never stored or executed as given; the fit keeps its
    n, k as numbers.
    """
    if eta_i_min > eta_i_max:
        raise HTTPException(
            status.HTTP_422_UNPROCESSABLE_CONTENT,
            f"`eta_i_range` must not be empty: eta_i_min {eta_i_min:g} > eta_i_max {eta_i_max:g}",
        )
    file_name = PurePath(file.filename or "").name
    fmt = format or PurePath(file_name).suffix.lstrip(".").lower()
    if fmt not in (*FORMATS, "yml", "txt"):
        raise HTTPException(
            status.HTTP_422_UNPROCESSABLE_CONTENT,
            f"`format` must be one of {', '.join(FORMATS)} (or a file name ending in one), "
            f"got {fmt or file_name!r}",
        )
    data = await file.read()
    display = (name or PurePath(file_name).stem or "uploaded").strip()[:200]
    with fit_errors():
        nk: SpectralNK = await run_in_threadpool(read_nk, data, fmt, display)
        if nk.wavelength_nm.size > MAX_NK_SAMPLES:
            raise ValueError(
                f"`file` must hold at most {MAX_NK_SAMPLES} wavelengths, got {nk.wavelength_nm.size}"
            )
    spec = NKFitSpec(
        kind="nk", name=display, source=nk.source, eta_i_range=(eta_i_min, eta_i_max),
        objective=objective, wavelength_nm=tuple(nk.wavelength_nm.tolist()),
        n=tuple(nk.n.tolist()), k=tuple(nk.k.tolist()), metrics_samples=settings.metrics_samples,
    )
    return await _answer(spec, store, runner, response)


@router.get("/{fit_id}", response_model=FitPublic, responses={**ERROR_RESPONSES, **NOT_FOUND})
def get_fit(fit_id: FitIdPath, store: StoreDep) -> FitPublic:
    """A stored fit."""
    return fit_public(stored_fit(store, fit_id))


@router.get(
    "/{fit_id}/pack",
    response_class=Response,
    responses={
        status.HTTP_200_OK: {"content": PACK_CONTENT, "description": "The download"},
        **ERROR_RESPONSES, **NOT_FOUND,
    },
)
def get_pack(
    fit_id: FitIdPath, store: StoreDep,
    format: Annotated[DownloadFormat, Query(
        description="binary | json | glsl | hlsl | mtlx | openpbr | blender | gltf")] = "binary",
    eta_i: Annotated[float, Query(
        ge=1.0, le=3.0, allow_inf_nan=False,
        description="Coating index of an export (mtlx, openpbr, blender, gltf), [1, 3]")] = 1.5,
) -> Response:
    """
    The fit as a download: ``binary`` (docs/pack-format.md), ``json``, or a
    ready-to-paste ``glsl`` / ``hlsl`` snippet with the coefficients and the
    evaluation function; or, for one coating index ``eta_i``, an export
    (docs/exports.md): a MaterialX document (``mtlx``: conductor under a
    dielectric coat; ``openpbr``: ``open_pbr_surface``), a Blender script
    (``blender``) or a glTF asset (``gltf``). Exports need the fit's measured
    n, k (422 for a fit made from curves alone).
    """
    record = stored_fit(store, fit_id)
    stem = f"{record.name}-{record.id[:8]}"
    if format not in EXPORT_MEDIA_TYPES:
        return pack_response([record], format, stem)
    with fit_errors():
        body = render_export(record, format, eta_i)
    stem = f"{stem}-eta{eta_i:g}"
    return Response(
        body, media_type=EXPORT_MEDIA_TYPES[format][0],
        headers={"Content-Disposition": f'attachment; filename="{download_name(stem, format)}"'},
    )


def pack_response(records: list[FitRecord], format: str, stem: str) -> Response:
    """A download with its media type and Content-Disposition file name."""
    body = render_pack(records, format, stem)
    media_type, _ = PACK_MEDIA_TYPES[format]
    return Response(
        body, media_type=media_type,
        headers={"Content-Disposition": f'attachment; filename="{download_name(stem, format)}"'},
    )


@router.get(
    "/{fit_id}/curves", response_model=CurvesPublic, responses={**ERROR_RESPONSES, **NOT_FOUND}
)
def get_curves(
    fit_id: FitIdPath, store: StoreDep,
    eta_i: Annotated[float, Query(ge=ETA_I_MIN, le=ETA_I_MAX, allow_inf_nan=False,
                                  description="Coating index")] = 1.5,
    samples: Annotated[int, Query(ge=2, le=1024, description="Angles from 0 to 90 degrees")] = 91,
) -> CurvesPublic:
    """
    Linear ACEScg reflectance against the angle theta in the coating, evenly
    from 0 to 90 degrees: the float16 model, the 1 nm spectral reference
    and adjusted Lazanyi (both None for fits without n, k).
    """
    record = stored_fit(store, fit_id)
    packed = material_from_json(record.material)
    theta = np.linspace(0.0, 90.0, samples)
    mu = cos_theta_from_angle(theta)
    model = model_ACEScg(packed.model, mu, eta_i, packed.coefficients, packed.eta_i_range)
    reference = baseline = None
    nk = measured_nk(record)
    if nk is not None:
        reference = reference_ACEScg(nk, mu, eta_i).tolist()
        inputs = baseline_inputs(nk)
        baseline = lazanyi_adjusted(mu, eta_i, inputs["F0_air"], inputs["F82_air"]).tolist()
    target = reference
    if record.kind == "curves":
        try:
            target = target_at(record, mu, eta_i)
        except ValueError:
            target = None  # no curve at this eta_i and no base to blend into
    return CurvesPublic(
        fit_id=record.id, eta_i=eta_i, theta_deg=theta.tolist(), cos_theta=mu.tolist(),
        model=model.tolist(), target=target, reference=reference, lazanyi_adjusted=baseline,
    )
