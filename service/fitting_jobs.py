"""
Fitting jobs
============

Content-addressed fits run in a bounded process pool, shared by every router
that makes fits (``fits``, ``curves``, ``scenes``).

-   :class:`NKFitSpec`: the inputs of an n, k fit; its
    ``fit_id`` is the content address of everything that determines the
    result.
-   :func:`nk_from_spec`: the validated :class:`fitting.nk.SpectralNK` of a spec.
-   :func:`measured_nk`: the n, k behind a stored fit, if any.
-   :class:`FitRunner`: the process pool with a bound on fits in flight and a
    time limit per fit.
-   :class:`Overloaded`, :class:`FitTimeout`, :class:`WorkerLost`: why a fit
    was not run (the HTTP edge answers 503, 504 and 503).
-   :func:`fit_nk`: look the id up in the store, else
    fit in the pool, build the :class:`service.store.FitRecord` and save it;
    return ``(record, created)``.

Fitting is CPU-bound (numpy, scipy): it runs in worker processes started
with ``spawn`` (forking a process that already runs threads or holds a GL
context is unsafe), never on the event loop, so reads stay fast while fits
run. The number of fits running or waiting is bounded; past the bound a fit
is refused at once with a ``Retry-After`` estimate instead of growing a
backlog. Identical requests in flight at the same time share one fit.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import math
import multiprocessing
import threading
import time
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict, dataclass
from typing import Any, Awaitable, Callable

import numpy as np

from fitting.colour.reference import spectral_grid, spectral_weights
from fitting.domain import DEFAULT_MIN_COVERAGE, check_eta_i_range
from fitting.fits.kinds import evaluate_model, fit_model
from fitting.fits.rgb_conductor import DEFAULT_SETTINGS as RGB_CONDUCTOR_SETTINGS
from fitting.fits.settings import DEFAULT_OBJECTIVE, FitSettings
from fitting.models.kinds import DEFAULT_MODEL
from fitting.models.pack import PackedMaterial, material_to_json
from fitting.optics.library import library_material
from fitting.optics.nk import SpectralNK, resample_nk

from .ids import content_id
from .store import FitRecord, Store

__all__ = [
    "FIT_FORMAT_VERSION",
    "NKFitSpec",
    "nk_from_spec",
    "check_finite",
    "fit_record",
    "measured_nk",
    "Overloaded",
    "FitTimeout",
    "WorkerLost",
    "FitRunner",
    "fit_nk",
]

FIT_FORMAT_VERSION = "fit/v1"
"""Part of every fit id: bump it when a change to the fit changes results."""


@dataclass(frozen=True)
class NKFitSpec:
    """
    A fit of measured n, k: a built-in material (``library_material`` set,
    arrays empty) or data given by the user (``kind`` "nk").

    ``eta_i_range`` is the coating-index domain [lo, hi], 1 <= lo <= hi <= 3;
    ``metrics_samples`` the side of the scoring grid of the metrics;
    ``model`` the model kind (:data:`fitting.models.kinds.MODEL_KINDS`).
    """

    kind: str
    name: str
    source: str
    eta_i_range: tuple[float, float]
    objective: str = DEFAULT_OBJECTIVE
    library_material: str | None = None
    wavelength_nm: tuple[float, ...] = ()
    n: tuple[float, ...] = ()
    k: tuple[float, ...] = ()
    metrics_samples: int = 100
    model: str = DEFAULT_MODEL

    @property
    def material_id(self) -> str:
        """The library name, or a content address of the data and its name."""
        if self.library_material is not None:
            return self.library_material
        return content_id("material", self.name, self.source, nk_from_spec(self).content_key())

    @property
    def fit_id(self) -> str:
        nk = nk_from_spec(self)
        lo, hi = self.eta_i_range
        # The default kind adds nothing, so coated-conductor ids stay as they were.
        kind = () if self.model == DEFAULT_MODEL else (self.model, repr(RGB_CONDUCTOR_SETTINGS))
        return content_id(
            FIT_FORMAT_VERSION, self.kind, self.name, self.source, nk.content_key(),
            repr((float(lo), float(hi))), self.objective, repr(FitSettings()),
            str(self.metrics_samples), *kind,
        )


def measured_nk(record: FitRecord) -> SpectralNK | None:
    """
    The measured n, k behind a stored fit: its library material's, or its
    stored data; None for a fit made from curves alone.
    """
    if record.library_material is not None:
        return library_material(record.library_material)
    if record.nk is None:
        return None
    return SpectralNK(
        np.asarray(record.nk["wavelength_nm"]), np.asarray(record.nk["n"]),
        np.asarray(record.nk["k"]), name=record.name, source=record.source,
    )


def nk_from_spec(spec: NKFitSpec) -> SpectralNK:
    """
    The validated n, k of a spec, checked to cover enough of 360-830 nm.

    Raises
    ------
    ValueError
        For an unknown library name, invalid data or too little coverage.
    """
    if spec.library_material is not None:
        nk = library_material(spec.library_material)
    else:
        nk = SpectralNK(
            np.asarray(spec.wavelength_nm, dtype=np.float64),
            np.asarray(spec.n, dtype=np.float64),
            np.asarray(spec.k, dtype=np.float64),
            name=spec.name,
            source=spec.source,
        )
    resample_nk(nk, spectral_grid(FitSettings().step_nm), DEFAULT_MIN_COVERAGE)
    return nk


def check_finite(what: str, values: dict[str, Any]) -> None:
    """Refuse (ValueError) a fit whose ``values`` hold NaN or infinity anywhere."""

    def walk(value):
        if isinstance(value, dict):
            return all(walk(v) for v in value.values())
        if isinstance(value, (list, tuple)):
            return all(walk(v) for v in value)
        if isinstance(value, float):
            return math.isfinite(value)
        return True

    if not walk(values):
        raise ValueError(f"the fit gave non-finite {what}: the data cannot be fitted")


def _nk_job(spec: NKFitSpec) -> dict[str, Any]:
    """Worker process: fit, quantise and score one material."""
    nk = nk_from_spec(spec)
    result = fit_model(nk, spec.eta_i_range, spec.model, objective=spec.objective)
    t0 = time.perf_counter()
    metrics = evaluate_model(nk, result, samples=spec.metrics_samples)
    timings = {**result.timings, "evaluate": time.perf_counter() - t0}
    packed = PackedMaterial(
        name=spec.name, coefficients=result.coefficients_float16,
        eta_i_range=result.eta_i_range, source=nk.source, model=result.model,
    )
    summary = result.summary()
    summary.pop("timings")
    check_finite("metrics", metrics)
    return {
        "material": material_to_json(packed),
        "metrics": metrics,
        "timings": timings,
        "convergence": summary,
        "coverage": result.coverage,
    }


def _warm_worker() -> None:
    """
    Worker start-up: import the fitting core and compute the spectral
    weights of the fit (5 nm) and of the metrics (1 nm) once, seconds that
    would otherwise land on the first fit.
    """
    spectral_weights(FitSettings().step_nm)
    spectral_weights(1.0)


def _ping() -> float:
    time.sleep(0.05)  # long enough that each warm-up ping lands on its own worker
    return time.time()


class Overloaded(Exception):
    """Too many fits in flight; ``retry_after`` is a wait estimate in seconds."""

    def __init__(self, retry_after: int, limit: int) -> None:
        super().__init__(
            f"the service is fitting {limit} materials already (the limit); "
            f"retry in about {retry_after} s"
        )
        self.retry_after = retry_after


class FitTimeout(Exception):
    """A fit ran past the time limit."""

    def __init__(self, limit_s: float) -> None:
        super().__init__(
            f"the fit did not finish within the time limit of {limit_s:g} s "
            "(COATED_FIT_TIMEOUT_S); retry later or with fewer samples"
        )


class WorkerLost(Exception):
    """A worker process died during the fit; the pool was restarted."""

    def __init__(self) -> None:
        super().__init__("a fitting worker process stopped during the fit; retry")


class FitRunner:
    """
    The bounded fitting pool.

    ``max_in_flight`` fits may run or wait at once; the next is refused
    with :class:`Overloaded`. Each fit has ``timeout_s`` seconds, waiting
    included; past it the caller gets :class:`FitTimeout` (the worker
    finishes the job in the background, and its slot stays taken until then
    so the bound stays true).
    """

    def __init__(self, workers: int, max_in_flight: int, timeout_s: float) -> None:
        if workers < 1 or max_in_flight < workers:
            raise ValueError(
                f"`max_in_flight` ({max_in_flight}) must be >= `workers` ({workers}) >= 1"
            )
        self.workers = workers
        self.max_in_flight = max_in_flight
        self.timeout_s = timeout_s
        self._lock = threading.Lock()
        self._in_flight = 0
        self._mean_s = 2.0  # running estimate of one fit's duration, for Retry-After
        self._pool: concurrent.futures.ProcessPoolExecutor | None = None
        self._pending: dict[str, asyncio.Future] = {}
        self.completed = 0

    @property
    def in_flight(self) -> int:
        return self._in_flight

    def _executor(self) -> concurrent.futures.ProcessPoolExecutor:
        with self._lock:
            if self._pool is None:
                self._pool = concurrent.futures.ProcessPoolExecutor(
                    max_workers=self.workers,
                    mp_context=multiprocessing.get_context("spawn"),
                    initializer=_warm_worker,
                )
            return self._pool

    def _restart(self, broken) -> None:
        with self._lock:
            if self._pool is broken:
                self._pool = None
        broken.shutdown(wait=False, cancel_futures=True)

    async def warm_up(self) -> None:
        """Start every worker process and wait until each has imported the core."""
        loop = asyncio.get_running_loop()
        pool = self._executor()
        await asyncio.gather(*(loop.run_in_executor(pool, _ping) for _ in range(self.workers)))

    def _retry_after(self) -> int:
        waves = math.ceil(self._in_flight / self.workers)
        return max(1, math.ceil(waves * self._mean_s))

    def _acquire(self) -> None:
        with self._lock:
            if self._in_flight >= self.max_in_flight:
                raise Overloaded(self._retry_after(), self.max_in_flight)
            self._in_flight += 1

    def _release(self, started: float, future: concurrent.futures.Future) -> None:
        with self._lock:
            self._in_flight -= 1
            if not future.cancelled() and future.exception() is None:
                self.completed += 1
                self._mean_s = 0.8 * self._mean_s + 0.2 * (time.perf_counter() - started)

    async def run(self, function: Callable[..., Any], *args: Any) -> Any:
        """
        Run ``function(*args)`` in a worker; its exceptions (ValueError for
        bad input) are raised here.

        Raises
        ------
        Overloaded, FitTimeout, WorkerLost
        """
        self._acquire()
        started = time.perf_counter()
        pool = self._executor()
        try:
            future = pool.submit(function, *args)
        except BaseException:
            with self._lock:
                self._in_flight -= 1
            self._restart(pool)
            raise WorkerLost() from None
        future.add_done_callback(lambda f: self._release(started, f))
        try:
            return await asyncio.wait_for(asyncio.wrap_future(future), self.timeout_s)
        except asyncio.TimeoutError:
            raise FitTimeout(self.timeout_s) from None
        except BrokenProcessPool:
            self._restart(pool)
            raise WorkerLost() from None

    async def once(self, key: str, make: Callable[[], Awaitable[Any]]) -> Any:
        """Await ``make()``, shared by concurrent calls with the same ``key``."""
        pending = self._pending.get(key)
        if pending is None:
            pending = asyncio.ensure_future(make())
            self._pending[key] = pending
            pending.add_done_callback(lambda _: self._pending.pop(key, None))
        return await asyncio.shield(pending)

    def close(self) -> None:
        with self._lock:
            pool, self._pool = self._pool, None
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)


def fit_record(fit_id: str, kind: str, material_id: str, name: str, source: str,
               job: dict[str, Any], objective: str, **extra: Any) -> FitRecord:
    """The record of a finished fitting job (material, metrics, timings, convergence)."""
    return FitRecord(
        id=fit_id, kind=kind, material_id=material_id, name=name, source=source,
        material=job["material"], metrics=job["metrics"], timings=job["timings"],
        convergence=job["convergence"], objective=objective, coverage=job.get("coverage"),
        created_at=time.time(), **extra,
    )


async def fit_nk(spec: NKFitSpec, store: Store, runner: FitRunner) -> tuple[FitRecord, bool]:
    """
    The stored fit of ``spec``: served from ``store`` when its id is there,
    otherwise fitted in ``runner``'s pool and saved. Returns
    ``(record, created)``.

    Raises
    ------
    ValueError
        For invalid input (checked here, before any work is queued).
    Overloaded, FitTimeout, WorkerLost
        From :meth:`FitRunner.run`.
    """
    check_eta_i_range(spec.eta_i_range)
    nk = nk_from_spec(spec)
    fit_id = spec.fit_id
    stored = await asyncio.to_thread(store.get_fit, fit_id)
    if stored is not None:
        # Asked for again: logged as the material's latest save.
        return await asyncio.to_thread(store.put_fit, stored), False

    async def make() -> FitRecord:
        job = await runner.run(_nk_job, spec)
        record = fit_record(
            fit_id, spec.kind, spec.material_id, spec.name, nk.source, job, spec.objective,
            library_material=spec.library_material,
            nk=None if spec.library_material else {
                "wavelength_nm": list(spec.wavelength_nm), "n": list(spec.n), "k": list(spec.k),
            },
            provenance={"fit_format": FIT_FORMAT_VERSION, "settings": asdict(FitSettings())},
        )
        return await asyncio.to_thread(store.put_fit, record)

    return await runner.once(fit_id, make), True
