"""
The process runtime
===================

Where the service's work runs, off the event loop, in processes of its own:

-   :class:`FitRunner`, the fitting pool: bounded, a time limit per job and
    a CPU-time limit per part (:class:`JobCPULimit`) and a CPU budget per
    job proportional to its estimated cost (:class:`JobBudgetExceeded`,
    :data:`BUDGET_FACTOR`), jobs no request waits
    for cancelled, a dead worker's jobs retried once and then alone, a job
    that kills a worker alone quarantined by its content id;
-   :class:`PreviewRunner`, the render pool: previews and GL textures in
    render processes, each with its own GL context (:func:`renderer`); a
    preview's CPU budget proportional to its estimated cost, one whose
    estimate passes the limit refused up front (:class:`RenderTooCostly`),
    one past its budget stopped (:class:`RenderBudgetExceeded`), and each
    client's previews admitted by their estimates;
-   the errors they raise, which ``service.api.errors`` maps to statuses:
    :class:`Overloaded` and :class:`PreviewsBusy` (503), :class:`FitTimeout`
    and :class:`PreviewTimeout` (504), :class:`WorkerLost`,
    :class:`WorkersNotStarted`, :class:`Quarantined`, :class:`RenderWorkerLost`
    and :class:`RendererUnavailable` (503), :class:`JobCPULimit`,
    :class:`JobBudgetExceeded`, :class:`RenderTooCostly` and
    :class:`RenderBudgetExceeded` (422);
-   the fair shares of the fitting pool (:class:`Shares`): each job's
    :class:`Claim` (its client and kind, set per request in :data:`CLAIM`),
    :class:`ShareExceeded` (503) past a client's share, and the saves per
    client per minute (:class:`SaveRate`, :class:`TooManySaves`: 429);
-   the process's own set-up: :func:`warm_process`, :func:`freeze_heap`,
    :func:`thaw_heap`; and for ``python -m service``, :func:`start_fork_server`
    (before any thread) and :func:`serve` (uvicorn with the connection
    bounds), imported on first use.

Inside (not for use outside this package): ``pool`` and ``previews`` (the two
pools), ``turns`` (the order parts run in), ``flights`` (one flight per
content key, the ring of cancelled jobs), ``executors`` (a pool stuck on a
half-written result unstuck), ``worker`` and ``render_worker`` (what runs in
each process), ``fork_server`` and ``preload`` (the processes are forks of a
fork server forked from the server), ``server`` (uvicorn's adapter) and
``mp_private`` (multiprocessing's private state), ``admission`` (the server's connection bounds), ``shares`` (the fair
shares), ``budget`` (each job's CPU budget); docs/architecture.md draws them.
"""

from __future__ import annotations

from typing import Any

from .budget import BUDGET_FACTOR, JobBudgetExceeded, RenderBudgetExceeded, RenderTooCostly
from .pool import FitRunner, FitTimeout, Overloaded, Quarantined, WorkerLost, WorkersNotStarted
from .previews import PreviewRunner, PreviewsBusy, PreviewTimeout, RenderWorkerLost
from .render_worker import RendererUnavailable, renderer
from .shares import CLAIM, Claim, SaveRate, ShareExceeded, Shares, TooManySaves
from .worker import JobCPULimit, freeze_heap, thaw_heap, warm_process

__all__ = [
    "FitRunner",
    "PreviewRunner",
    "Overloaded",
    "FitTimeout",
    "WorkerLost",
    "WorkersNotStarted",
    "Quarantined",
    "JobCPULimit",
    "JobBudgetExceeded",
    "BUDGET_FACTOR",
    "RenderTooCostly",
    "RenderBudgetExceeded",
    "PreviewsBusy",
    "PreviewTimeout",
    "RenderWorkerLost",
    "RendererUnavailable",
    "Shares",
    "Claim",
    "CLAIM",
    "ShareExceeded",
    "SaveRate",
    "TooManySaves",
    "renderer",
    "warm_process",
    "freeze_heap",
    "thaw_heap",
    "start_fork_server",
    "serve",
]

_ON_FIRST_USE = {"start_fork_server": "fork_server", "serve": "server"}
"""Entry points of ``python -m service`` whose modules (uvicorn, the fork server's) load when first asked for."""


def __getattr__(name: str) -> Any:
    if name in _ON_FIRST_USE:
        import importlib

        return getattr(importlib.import_module(f".{_ON_FIRST_USE[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
