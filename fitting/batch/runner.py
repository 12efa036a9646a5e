"""
Running a batch
===============

-   :func:`run_batch`: fit a selection of pages into an output directory, in
    this process, in a pool of local worker processes, or on a Dask cluster.
-   :class:`BatchResult`: what a run did.

Every finished page is journaled (:class:`fitting.batch.journal.Journal`)
before it counts, so a run stopped at any point (Ctrl-C, a killed process)
and started again with the same arguments fits only what is missing. On a
Dask cluster (``scheduler``, a ``dask.distributed`` address) a page whose
worker dies is re-run by the scheduler on another worker; the journal keeps
the first finished record of each page. Outputs are written from the journal
sorted by page (:mod:`fitting.batch.report`), so they do not depend on the
order pages finish in.
"""

from __future__ import annotations

import concurrent.futures
import hashlib
import json
import multiprocessing
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ..domain import DEFAULT_MIN_COVERAGE, check_eta_i_range
from .journal import Journal
from .kinds import DEFAULT_MODEL_KIND, check_model_kinds
from .page import REPORTED_BASELINES, fit_page
from .report import write_outputs

__all__ = ["BatchResult", "Progress", "run_batch"]


class Progress:
    """A progress bar on a text stream (stderr): redrawn in place on a terminal, a line per 10% otherwise."""

    def __init__(self, total: int, done: int = 0, stream=None, enabled: bool = True) -> None:
        self.total, self.done, self.start_done = total, done, done
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.t0 = time.perf_counter()
        self._last_decile = -1
        self.update(0)

    def update(self, step: int = 1) -> None:
        self.done += step
        if not self.enabled:
            return
        fraction = self.done / self.total if self.total else 1.0
        decile = int(fraction * 10)
        if not self.tty and decile == self._last_decile and self.done != self.total:
            return
        self._last_decile = decile
        elapsed = time.perf_counter() - self.t0
        rate = (self.done - self.start_done) / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        bar = "#" * int(fraction * 30)
        text = (
            f"[{bar:<30s}] {self.done}/{self.total} pages  {rate:5.2f} pages/s  "
            f"{'left ' + format(left, '.0f') + ' s' if left == left else ''}"
        )
        self.stream.write(("\r" + text) if self.tty else (text + "\n"))
        if self.tty and self.done == self.total:
            self.stream.write("\n")
        self.stream.flush()


@dataclass
class BatchResult:
    """``pages`` selected, ``fitted_now`` (pages fitted by this run, the rest came from the journal), ``summary`` (:func:`fitting.batch.report.accuracy_summary`), ``wall_s``, ``output``."""

    pages: int
    fitted_now: int
    summary: dict[str, Any]
    wall_s: float
    output: Path
    records: list[dict[str, Any]] = field(repr=False, default_factory=list)


def _config(pages, kinds, eta_i_range, samples, min_coverage) -> dict[str, Any]:
    digest = hashlib.sha256("\n".join(pages).encode("utf-8")).hexdigest()[:32]
    return {
        "pages": len(pages),
        "pages_sha256": digest,
        "model_kinds": list(kinds),
        "eta_i_range": list(eta_i_range),
        "grid": f"{samples}x{samples}",
        "reference_step_nm": 1.0,
        "min_coverage": min_coverage,
        "baselines": list(REPORTED_BASELINES),
    }


def _check_workers(workers) -> int:
    if workers is None:
        return os.cpu_count() or 1
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"`workers` must be an integer >= 1, got {workers!r}")
    return workers


def _serial(todo, args, sink):
    for page in todo:
        sink(fit_page(page, *args))


def _local_pool(todo, args, sink, workers):
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(workers, mp_context=context) as pool:
        futures = [pool.submit(fit_page, page, *args) for page in todo]
        try:
            for future in concurrent.futures.as_completed(futures):
                sink(future.result())
        except BaseException:
            for future in futures:
                future.cancel()
            raise


def _dask(todo, args, sink, scheduler, config):
    from distributed import Client, as_completed
    from distributed.scheduler import KilledWorker

    token = hashlib.sha256(json.dumps(config, sort_keys=True).encode("utf-8")).hexdigest()[:16]
    client = scheduler if isinstance(scheduler, Client) else Client(scheduler)
    try:
        futures = {
            client.submit(fit_page, page, *args, key=f"fit_page-{token}-{page}", pure=False): page for page in todo
        }
        try:
            for future in as_completed(futures):
                page = futures[future]
                try:
                    sink(future.result())
                except KilledWorker:
                    # The page itself took down every worker it ran on.
                    sink(
                        {
                            "page": page,
                            "status": "failed",
                            "reason": "its worker died on every try",
                            "coverage": None,
                            "wavelength_range_nm": None,
                            "kinds": {},
                            "baselines": {},
                            "materials": {},
                            "seconds": 0.0,
                        }
                    )
        finally:
            client.cancel(list(futures))
    finally:
        if client is not scheduler:
            client.close()


def run_batch(
    pages: list[str],
    output: str | Path,
    kinds=(DEFAULT_MODEL_KIND,),
    eta_i_range=(1.0, 2.5),
    workers: int | None = None,
    scheduler=None,
    samples: int = 100,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
    progress: bool = True,
    on_record: Callable[[dict[str, Any]], None] | None = None,
    stream=None,
) -> BatchResult:
    """
    Fit ``pages`` (``SHELF/BOOK/PAGE``, see :func:`fitting.batch.select_pages`)
    with every model kind of ``kinds`` over ``eta_i_range`` and write the
    pack and report into the directory ``output``.

    Parameters
    ----------
    workers
        Local worker processes (default: every core); 1 runs in this process.
        Ignored with ``scheduler``.
    scheduler
        A ``dask.distributed`` scheduler address (``tcp://host:8786``) or a
        ``Client``: the pages run as tasks on that cluster.
    samples
        The scoring grid is ``samples`` x ``samples`` (the paper's 100).
    on_record
        Called in this process with each newly journaled record.

    Returns
    -------
    BatchResult

    Raises
    ------
    ValueError
        For an empty selection, an unknown kind, a bad domain or worker
        count, or an output directory holding another batch's journal.
    """
    t0 = time.perf_counter()
    pages = sorted(set(pages))
    if not pages:
        raise ValueError("`pages` must name at least one page")
    kinds = check_model_kinds(kinds)
    eta_i_range = tuple(float(v) for v in check_eta_i_range(eta_i_range))
    if isinstance(samples, bool) or not isinstance(samples, int) or not 2 <= samples <= 1000:
        raise ValueError(f"`samples` must be an integer in [2, 1000], got {samples!r}")
    workers = _check_workers(workers)
    config = _config(pages, kinds, eta_i_range, samples, min_coverage)
    output = Path(output)
    args = (kinds, eta_i_range, samples, min_coverage)
    with Journal(output, config) as journal:
        todo = [p for p in pages if p not in journal.records]
        bar = Progress(len(pages), len(pages) - len(todo), stream, enabled=progress)
        fitted_now = 0

        def sink(record):
            nonlocal fitted_now
            if record["page"] in journal.records:
                return
            journal.append(record)
            fitted_now += 1
            bar.update()
            if on_record is not None:
                on_record(record)

        if todo:
            if scheduler is not None:
                _dask(todo, args, sink, scheduler, config)
            elif workers == 1 or len(todo) == 1:
                _serial(todo, args, sink)
            else:
                _local_pool(todo, args, sink, min(workers, len(todo)))
        records = [journal.records[p] for p in pages]
        wall = time.perf_counter() - t0
        # Still under the journal's lock: two runs never write the outputs at once.
        summary = write_outputs(output, records, config, kinds, tuple(REPORTED_BASELINES), wall)
    return BatchResult(len(pages), fitted_now, summary, wall, output, records)
