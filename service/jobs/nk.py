"""
n, k fits
=========

-   :class:`NKFit`: a validated fit of measured n, k (a built-in material or
    data given by the user): the :class:`fitting.optics.nk.SpectralNK` built and
    checked once, and the ids computed once.
-   :func:`fit_nk`: the stored fit of an :class:`NKFit`, else fitted in the
    pool and saved (its metrics evaluated later, :mod:`service.jobs.evaluation`);
    ``(record, created)``.
-   :func:`angle_curves`: the float16 model, the spectral reference and
    adjusted Lazanyi of a stored fit against the angle (for plotting).
"""

from __future__ import annotations

import asyncio
from pathlib import PurePath
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from fitting.colour.reference import reference_ACEScg, spectral_grid
from fitting.domain import DEFAULT_MIN_COVERAGE, BoundedCache, check_eta_i_range, cos_theta_from_angle
from fitting.fits.kinds import fit_kind, fit_model
from fitting.fits.pipeline import with_metrics
from fitting.fits.settings import DEFAULT_OBJECTIVE, FitSettings
from fitting.models.baselines import baseline_inputs, lazanyi_adjusted
from fitting.models.kinds import DEFAULT_MODEL, model_ACEScg
from fitting.models.pack import material_from_json, material_to_json
from fitting.optics.catalogue import catalogue_material, resolve_material
from fitting.optics.nk import SpectralNK, resample_nk
from fitting.optics.readers import FORMATS, read_nk

from ..runtime import FitRunner
from ..store import FitRecord, Store
from .curves import target_at
from .evaluation import Evaluations, ensure_metrics, evaluation_provenance, solve_metrics
from .common import (
    FIT_FORMAT_VERSION,
    check_finite,
    checked_writable,
    content_address,
    fit_record,
    measured_nk,
    nk_view,
)

__all__ = ["NKFit", "fit_nk", "angle_curves", "MAX_NK_SAMPLES"]

MAX_NK_SAMPLES = 20_000
"""Most wavelength samples accepted in one n, k table."""

PART_COST_S = 0.1
"""Estimated seconds of an n, k fit: its turn in the pool (:class:`service.runtime.turns.Turns`)."""


@dataclass(frozen=True)
class NKFit:
    """
    A validated n, k fit: ``nk`` checked (and checked to cover enough of
    360-830 nm) once, ``eta_i_range`` checked, ``fit_id`` and ``material_id``
    computed once; ``model`` the model kind
    (:data:`fitting.models.kinds.MODEL_KINDS`). Make it with :meth:`library`
    or :meth:`data`.
    """

    kind: str
    name: str
    nk: SpectralNK
    eta_i_range: tuple[float, float]
    objective: str
    metrics_samples: int
    library_material: str | None
    fit_id: str
    material_id: str
    model: str = DEFAULT_MODEL

    @classmethod
    def _make(
        cls,
        kind: str,
        name: str,
        nk: SpectralNK,
        eta_i_range,
        objective: str,
        metrics_samples: int,
        library: str | None,
        model: str = DEFAULT_MODEL,
    ) -> "NKFit":
        lo, hi = check_eta_i_range(eta_i_range)
        if nk.wavelength_nm.size > MAX_NK_SAMPLES:
            raise ValueError(f"`nk` must hold at most {MAX_NK_SAMPLES} wavelengths, got {nk.wavelength_nm.size}")
        resample_nk(nk, spectral_grid(FitSettings().step_nm), DEFAULT_MIN_COVERAGE)
        arrays = [nk.wavelength_nm, nk.n, nk.k]
        fit_id = content_address(
            FIT_FORMAT_VERSION,
            kind,
            name,
            nk.source,
            arrays,
            [lo, hi],
            objective,
            repr(FitSettings()),
            metrics_samples,
            # The default kind adds nothing, so coated-conductor ids stay as they were.
            *(() if model == DEFAULT_MODEL else (model, repr(fit_kind(model).settings))),
        )
        material_id = library or content_address("material", name, nk.source, arrays)
        return cls(kind, name, nk, (lo, hi), objective, metrics_samples, library, fit_id, material_id, model)

    @classmethod
    def library(
        cls,
        material: str,
        eta_i_range,
        objective: str = DEFAULT_OBJECTIVE,
        metrics_samples: int = 100,
        model: str = DEFAULT_MODEL,
    ) -> "NKFit":
        """A fit of a library conductor by name, symbol or id (ValueError for an unknown one)."""
        material = resolve_material(material)
        return cls._make(
            "library", material, catalogue_material(material), eta_i_range, objective, metrics_samples, material, model
        )

    @classmethod
    def data(
        cls,
        name: str,
        source: str,
        wavelength_nm,
        n,
        k,
        eta_i_range,
        objective: str = DEFAULT_OBJECTIVE,
        metrics_samples: int = 100,
        model: str = DEFAULT_MODEL,
    ) -> "NKFit":
        """A fit of measured data (ValueError for invalid data or too little coverage)."""
        nk = SpectralNK(
            np.asarray(wavelength_nm, dtype=np.float64),
            np.asarray(n, dtype=np.float64),
            np.asarray(k, dtype=np.float64),
            name=name,
            source=source,
        )
        return cls._make("nk", name, nk, eta_i_range, objective, metrics_samples, None, model)

    @classmethod
    def from_nk(
        cls,
        nk: SpectralNK,
        eta_i_range,
        objective: str = DEFAULT_OBJECTIVE,
        metrics_samples: int = 100,
        model: str = DEFAULT_MODEL,
    ) -> "NKFit":
        """A fit of an n, k already read (an upload), of the model kind ``model``."""
        return cls._make("nk", nk.name, nk, eta_i_range, objective, metrics_samples, None, model)

    @classmethod
    def upload(
        cls,
        data: bytes,
        file_name: str,
        format: str | None,
        name: str | None,
        eta_i_range,
        objective: str = DEFAULT_OBJECTIVE,
        metrics_samples: int = 100,
        model: str = DEFAULT_MODEL,
    ) -> "NKFit":
        """
        A fit of an uploaded file: ``format`` (csv, json, yaml) or the file
        name's suffix; the display name ``name`` or the file's stem; the
        model kind ``model``.
        """
        lo, hi = eta_i_range
        if lo > hi:
            raise ValueError(f"`eta_i_range` must not be empty: eta_i_min {lo:g} > eta_i_max {hi:g}")
        file_name = PurePath(file_name).name
        fmt = format or PurePath(file_name).suffix.lstrip(".").lower()
        if fmt not in (*FORMATS, "yml", "txt"):
            raise ValueError(
                f"`format` must be one of {', '.join(FORMATS)} (or a file name ending in one), "
                f"got {(fmt or file_name)[:40]!r}"
            )
        display = (name or PurePath(file_name).stem or "uploaded").strip()[:200]
        # The row limit is checked on the line count, before any number is parsed.
        return cls.from_nk(read_nk(data, fmt, display, MAX_NK_SAMPLES), eta_i_range, objective, metrics_samples, model)


def _fit_part(fit: NKFit) -> dict[str, Any]:
    """
    Worker process: fit and quantise one material; the job's answer, its
    metrics those of the solve (:func:`service.jobs.evaluation.solve_metrics`:
    the evaluation on the metrics grid comes later, once).
    """
    result = fit_model(fit.nk, fit.eta_i_range, fit.model, objective=fit.objective)
    with_metrics(result, solve_metrics(result, result.coverage), name=fit.name)
    summary = result.summary()
    summary.pop("timings")
    check_finite("coefficients", result.coefficients.tolist())
    return {
        "material": material_to_json(result.packed),
        "metrics": result.metrics,
        "timings": result.timings,
        "convergence": summary,
        "coverage": result.coverage,
        "settings": asdict(result.settings),
        "evaluation": evaluation_provenance(result, fit.metrics_samples),
    }


async def fit_nk(
    fit: NKFit, store: Store, runner: FitRunner, evaluations: Evaluations | None = None, metrics: bool = False
) -> tuple[FitRecord, bool]:
    """
    The stored fit of ``fit``: served from ``store`` when its id is there,
    otherwise fitted in ``runner``'s pool (one part, one worker) and saved
    with the metrics of its solve, its evaluation on the metrics grid left
    to ``evaluations`` (in the background) or to whoever asks for it; with
    ``metrics`` true, evaluated before the answer
    (:func:`service.jobs.evaluation.ensure_metrics`). Returns ``(record, created)``.

    Raises
    ------
    StoreError
        When the store cannot take the save (checked before any fitting).
    Overloaded, FitTimeout, WorkerLost
        From :class:`service.runtime.pool.FitRunner`.
    """

    def stored_or_writable() -> FitRecord | None:
        """The stored fit, asked for again (logged as the material's latest save), else None once the
        store can take a save (one trip to a thread for both)."""
        stored = store.get_fit(fit.fit_id)
        if stored is not None:
            return store.put_fit(stored)
        checked_writable(store)
        return None

    record = await asyncio.to_thread(stored_or_writable)
    if record is not None:
        return (await ensure_metrics(record, store, runner) if metrics else record), False

    async def make() -> FitRecord:
        job = await runner.run(_fit_part, fit, cost_s=PART_COST_S)
        record = fit_record(
            fit.fit_id,
            fit.kind,
            fit.material_id,
            fit.name,
            fit.nk.source,
            job,
            fit.objective,
            library_material=fit.library_material,
            nk=None if fit.library_material else nk_view(fit.nk),
            # The settings that ran (the kind's, with the request's objective), and what the
            # evaluation of its metrics needs.
            provenance={"fit_format": FIT_FORMAT_VERSION, "settings": job["settings"], **job["evaluation"]},
        )
        return await asyncio.to_thread(store.put_fit, record)

    record = await runner.once(fit.fit_id, make)
    if metrics:
        record = await ensure_metrics(record, store, runner)
    elif evaluations is not None:
        evaluations.schedule(record.id)
    return record, True


_MEASURED_CURVES = BoundedCache(64)


def _measured_curves(nk: SpectralNK, eta_i: float, samples: int) -> tuple[list, list]:
    """
    (1 nm reference, adjusted Lazanyi) of ``nk`` at ``eta_i`` against the
    angle: they depend on the measured data alone, not on the fit, so every
    refit of one material (an editor drag asks for one per step) reuses
    them; the most recent few are kept.
    """

    def build() -> tuple[list, list]:
        mu = cos_theta_from_angle(np.linspace(0.0, 90.0, samples))
        inputs = baseline_inputs(nk)
        return (
            reference_ACEScg(nk, mu, eta_i).tolist(),
            lazanyi_adjusted(mu, eta_i, inputs["F0_air"], inputs["F82_air"]).tolist(),
        )

    return _MEASURED_CURVES.get((nk.content_key(), eta_i, samples), build)


def angle_curves(record: FitRecord, eta_i: float, samples: int) -> dict[str, Any]:
    """
    Linear ACEScg reflectance of a stored fit against the angle theta in the
    coating, evenly from 0 to 90 degrees: the float16 model, the 1 nm
    spectral reference and adjusted Lazanyi (both None without n, k).
    """
    packed = material_from_json(record.material)
    theta = np.linspace(0.0, 90.0, samples)
    mu = cos_theta_from_angle(theta)
    model = model_ACEScg(packed.model, mu, eta_i, packed.coefficients, packed.eta_i_range)
    reference = baseline = None
    nk = measured_nk(record)
    if nk is not None:
        reference, baseline = _measured_curves(nk, float(eta_i), int(samples))
    target = reference
    if record.kind == "curves":
        try:
            target = target_at(record, mu, eta_i)
        except ValueError:
            target = None  # no curve at this eta_i and no base to blend into
    return {
        "fit_id": record.id,
        "eta_i": eta_i,
        "theta_deg": theta.tolist(),
        "cos_theta": mu.tolist(),
        "model": model.tolist(),
        "target": target,
        "reference": reference,
        "lazanyi_adjusted": baseline,
    }
