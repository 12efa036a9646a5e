"""
A fit's metrics, evaluated once
===============================

An n, k fit answers with what its own solve measured; its evaluation on the
metrics grid (Delta E 2000 of the float16 and float64 model and of every
baseline against the 1 nm spectral reference, 100 x 100 by default: about
as much CPU as the fit) runs once per fit, when something asks for a figure
that needs it, or in the background once the pool has been idle a while,
and its JSON is stored with the fit (:meth:`service.store.Store.set_metrics`).

-   :func:`solve_metrics`: the metrics JSON a fit is saved with (``evaluated``
    false): coverage, what the solve measured (``guard``: the worst-case
    guard's candidates on its points), the quality report.
-   :func:`evaluated`: whether a stored fit's metrics are the full ones
    (records saved before the evaluation was deferred are).
-   :func:`ensure_metrics`: a stored fit with its full metrics, evaluated in
    the pool when it has none yet (one flight per fit across requests).
-   :class:`Evaluations`: the background evaluation of fits saved without
    metrics, one at a time and only after the pool has been idle
    ``idle_s``; at most :data:`PENDING_LIMIT` wait (the oldest are dropped,
    and evaluated when asked for).

The evaluation is one part in one worker: the reference and the baselines'
scores are computed and kept there (:data:`_REFERENCES`, per worker, for
the most recent materials), so no grid crosses a process boundary; only
the metrics JSON comes back.
"""

from __future__ import annotations

import asyncio
import collections
import dataclasses
import logging
import types
from typing import Any

import numpy as np

from fitting.colour.reference import evaluation_grid, reference_ACEScg_grid
from fitting.domain import DEFAULT_MIN_COVERAGE, BoundedCache
from fitting.fits.evaluate import metrics_json, score_on_grid
from fitting.models.kinds import model_ACEScg
from fitting.models.pack import material_from_json
from fitting.optics.nk import SpectralNK

from ..runtime import FitRunner
from ..store import FitRecord, Store
from .common import check_finite, measured_nk, with_measured_nk

__all__ = [
    "METRICS_DTYPE",
    "PENDING_LIMIT",
    "solve_metrics",
    "evaluated",
    "evaluation_provenance",
    "ensure_metrics",
    "Evaluations",
]

log = logging.getLogger("service.evaluation")

METRICS_DTYPE = "float32"
"""
Arithmetic of the spectral reference of a fit's metrics: float32, nearly
twice as fast as the float64 definition, its Delta E within 0.001 of it
(measured 7e-6, the same on every CPU; see
:func:`fitting.colour.reference.reference_ACEScg_grid`; docs/service.md).
"""

EVALUATE_COST_S = 0.1
"""Estimated seconds of an evaluation: its turn in the pool (:class:`service.runtime.turns.Turns`)."""

PENDING_LIMIT = 256
"""Fits waiting for a background evaluation at most (the oldest are dropped, evaluated when asked for)."""

_REFERENCES = BoundedCache(8)  # in a worker: (reference, baselines' scores) of the most recent materials


def solve_metrics(result, coverage: float | None) -> dict[str, Any]:
    """
    The metrics JSON a fit of ``result`` is saved with before its
    evaluation: ``evaluated`` false, ``coverage``, ``quality`` (what the
    fit can be trusted for) and ``guard``, the figures the solve measured
    itself (the worst-case guard's candidates: Delta E 2000 on its points,
    and which it kept), where it ran. Once evaluated, the metrics are those
    of :func:`fitting.fits.pipeline.fit_spectral` with ``evaluate``
    (``evaluated`` gone).
    """
    out: dict[str, Any] = {"evaluated": False, "coverage": coverage}
    if result.quality:
        out["quality"] = result.quality
    if result.guard is not None:
        out["guard"] = result.guard
    return out


def evaluated(record: FitRecord) -> bool:
    """True when ``record``'s metrics are complete (every kind but an n, k fit saved before its evaluation)."""
    return (record.metrics or {}).get("evaluated", True) is not False


def evaluation_provenance(result, samples: int) -> dict[str, Any]:
    """What the evaluation needs of a fit that the record does not otherwise keep (its provenance)."""
    return {
        "coefficients_float64": np.asarray(result.coefficients, dtype=np.float64).tolist(),
        "metrics_samples": int(samples),
    }


def _reference(nk: SpectralNK, library: str | None, eta_i_range: tuple[float, float], samples: int):
    """Worker: the 1 nm reference on the metrics grid and the baselines' scores against it (kept, per material)."""

    def build():
        M, E = evaluation_grid(samples, eta_i_range)
        reference = reference_ACEScg_grid(nk, M[0], E[:, 0], 1.0, DEFAULT_MIN_COVERAGE, METRICS_DTYPE)
        reference.flags.writeable = False
        return reference, score_on_grid(nk, M, E, {}, reference=reference)

    key = (library or nk.content_key(), float(eta_i_range[0]), float(eta_i_range[1]), int(samples))
    return _REFERENCES.get(key, build)


def _evaluate_part(
    nk: SpectralNK,
    library: str | None,
    material: dict[str, Any],
    coefficients_float64,
    samples: int,
    coverage: float | None,
) -> dict[str, Any]:
    """Worker: the metrics JSON of one fit (:func:`fitting.fits.evaluate.metrics_json`), its grids kept here."""
    packed = material_from_json(material)
    eta_i_range = tuple(float(x) for x in packed.eta_i_range)
    reference, baselines = _reference(nk, library, eta_i_range, samples)
    M, E = evaluation_grid(samples, eta_i_range)
    models = {
        name: model_ACEScg(packed.model, M, E, np.asarray(coefficients, dtype=np.float64), eta_i_range)
        for name, coefficients in (("model_float16", packed.coefficients), ("model_float64", coefficients_float64))
    }
    errors = score_on_grid(nk, M, E, models, baselines=False, reference=reference)
    # metrics_json reads the fit's coverage and quality and sets its ``error``: a stand-in of the fit
    # carries them (the quality report stays the solve's: ensure_metrics keeps it beside the evaluation).
    fit = types.SimpleNamespace(coverage=coverage, quality=None, error=None)
    metrics = metrics_json({**errors, **baselines}, fit, samples)
    check_finite("metrics", metrics)
    return metrics


async def ensure_metrics(record: FitRecord, store: Store, runner: FitRunner) -> FitRecord:
    """
    ``record`` with its full metrics: as it is when they are there, else
    evaluated in ``runner``'s pool (one flight per fit, shared by every
    request that asks meanwhile, under the pool's bound and time limit),
    stored, and the record as stored returned.

    Raises
    ------
    Overloaded, FitTimeout, WorkerLost
        From :class:`service.runtime.FitRunner`.
    """
    if evaluated(record):
        return record

    async def make() -> FitRecord:
        fresh = await asyncio.to_thread(store.get_fit, record.id)
        if fresh is not None and evaluated(fresh):  # another replica (or an earlier flight) evaluated it
            return fresh
        full = (
            record
            if record.nk is not None or record.library_material
            else await asyncio.to_thread(with_measured_nk, store, record)
        )
        nk = measured_nk(full)
        if nk is None:
            raise LookupError(f"the measured n, k of fit {record.id} are no longer stored: it cannot be evaluated")
        provenance = record.provenance or {}
        pending = record.metrics or {}
        metrics = await runner.run(
            _evaluate_part,
            nk,
            record.library_material,
            record.material,
            provenance["coefficients_float64"],
            int(provenance.get("metrics_samples", 100)),
            pending.get("coverage"),
            cost_s=EVALUATE_COST_S,
        )
        # The quality report and what the solve measured stay beside the evaluation, as the core's
        # fit_spectral(evaluate=True) has them.
        metrics = {**metrics, **{key: pending[key] for key in ("quality", "guard") if key in pending}}
        stored = await asyncio.to_thread(store.set_metrics, record.id, metrics)
        return stored if stored is not None else dataclasses.replace(record, metrics=metrics)

    done = await runner.once(f"metrics {record.id}", make)
    # The caller's record (its n, k filled in, where it was) with the stored metrics.
    return dataclasses.replace(record, metrics=done.metrics)


class Evaluations:
    """
    The background evaluation of fits saved without metrics
    (:func:`ensure_metrics`): one at a time, each once the pool has had no
    job for ``idle_s`` seconds (so it never takes a worker from a request,
    and a steady load defers it); ``idle_s`` None: none in the background.
    """

    def __init__(self, store: Store, runner: FitRunner, idle_s: float | None = 1.0) -> None:
        self.store, self.runner, self.idle_s = store, runner, idle_s
        self._pending: collections.OrderedDict[str, None] = collections.OrderedDict()
        self._task: asyncio.Task | None = None
        self.done = 0

    def schedule(self, fit_id: str) -> None:
        """Evaluate ``fit_id`` in the background, when the pool is idle (the oldest dropped past the limit)."""
        if self.idle_s is None:
            return
        self._pending[fit_id] = None
        while len(self._pending) > PENDING_LIMIT:
            self._pending.popitem(last=False)
        if self._task is None or self._task.done():
            self._task = asyncio.get_running_loop().create_task(self._drain())

    async def _idle(self) -> None:
        """Return once the pool has had nothing in flight for ``idle_s`` seconds."""
        quiet = 0.0
        step = min(0.1, self.idle_s)
        while quiet < self.idle_s:
            await asyncio.sleep(step)
            quiet = quiet + step if self.runner.in_flight == 0 else 0.0

    async def _drain(self) -> None:
        while self._pending:
            await self._idle()
            if not self._pending:
                break
            fit_id, _ = self._pending.popitem(last=False)
            try:
                record = await asyncio.to_thread(self.store.get_fit, fit_id)
                if record is not None and not evaluated(record):
                    await ensure_metrics(record, self.store, self.runner)
                    self.done += 1
            except asyncio.CancelledError:
                raise
            except Exception as error:  # it is evaluated when asked for instead
                log.info("background evaluation of fit %s skipped: %r", fit_id[:16], error)

    def close(self) -> None:
        self._pending.clear()
        if self._task is not None:
            self._task.cancel()
