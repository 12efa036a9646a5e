"""
A CPU budget per job
====================

Every part of a job has the pool's CPU-time limit (``COATED_JOB_CPU_LIMIT_S``),
but a job of many parts (a scene: one part per material, each fitted at its
eta_i) could use that limit once per part: 64 materials, 64 limits. So each
job has a budget of CPU seconds proportional to what it asked for:
:data:`BUDGET_FACTOR` times its estimated cost (the same estimate its turn is
ordered by), and never less than one part's limit (a single fit's estimate is
rough; its limit is the part limit, as before).

-   :class:`JobBudget`: the budget of one job, charged with the CPU time of
    each part as it ends; a part starts with what is left as its limit.
-   :data:`BUDGET`: the running job's budget (a context variable set by
    :meth:`service.runtime.pool.FitRunner.slot`; its parts inherit it).
-   :class:`JobBudgetExceeded`: the job used its budget (a 422 naming it):
    the part that went past it is stopped, and so are the job's other
    parts (a scene's first failure cancels the rest).
-   :func:`run_part_timed`: in a worker, a part and the CPU time it used;
    :func:`part_limit` and :func:`charged`: the pool's side of a part.

A render (a preview, one part) has a budget the same way:
:func:`render_budget_s` is :data:`BUDGET_FACTOR` times its estimated CPU
seconds, at least :data:`RENDER_BUDGET_FLOOR_S` and at most the CPU-time
limit of a job; a render whose estimate alone passes that limit is refused
before it starts (:class:`RenderTooCostly`, 422 naming the limit), and one
that uses its budget is stopped (:class:`RenderBudgetExceeded`, 422).
"""

from __future__ import annotations

import contextvars
import threading
import time
from typing import Any, Awaitable, Callable

from .worker import JobCPULimit, run_part

__all__ = [
    "BUDGET_FACTOR",
    "BUDGET",
    "JobBudget",
    "JobBudgetExceeded",
    "run_part_timed",
    "part_limit",
    "charged",
    "RENDER_BUDGET_FLOOR_S",
    "render_budget_s",
    "RenderTooCostly",
    "RenderBudgetExceeded",
]

BUDGET_FACTOR = 3.0
"""A job may use this many times its estimated CPU seconds (a 64 x 32 scene: 2,048 parts of 0.03 s, 184 s)."""


class JobBudgetExceeded(ValueError):
    """A job used its CPU budget and was stopped (422)."""

    def __init__(self, limit_s: float, estimate_s: float) -> None:
        super().__init__(
            f"the job used its CPU budget of {limit_s:.1f} s ({BUDGET_FACTOR:g} x its estimated {estimate_s:.1f} s, "
            "at least COATED_JOB_CPU_LIMIT_S) and was stopped; make the request smaller"
        )
        self.limit_s, self.estimate_s = limit_s, estimate_s

    def __reduce__(self):
        return JobBudgetExceeded, (self.limit_s, self.estimate_s)


class JobBudget:
    """The CPU seconds one job may use: ``max(part_limit_s, BUDGET_FACTOR * estimate_s)``."""

    def __init__(self, estimate_s: float, part_limit_s: float) -> None:
        self.estimate_s = float(estimate_s)
        self.limit_s = max(float(part_limit_s), BUDGET_FACTOR * self.estimate_s)
        self.used_s = 0.0
        self._lock = threading.Lock()

    def part_limit(self, part_limit_s: float) -> float:
        """The CPU limit of the next part: what is left (:class:`JobBudgetExceeded` when nothing is)."""
        with self._lock:
            left = self.limit_s - self.used_s
        if left <= 0.0:
            raise JobBudgetExceeded(self.limit_s, self.estimate_s)
        return min(part_limit_s, left)

    def charge(self, cpu_s: float) -> None:
        with self._lock:
            self.used_s += max(0.0, cpu_s)


BUDGET: contextvars.ContextVar[JobBudget | None] = contextvars.ContextVar("budget", default=None)
"""The running job's budget (None outside a job: the part limit alone)."""


def run_part_timed(serial: int, cpu_limit_s: float, function: Callable[..., Any], *args: Any) -> tuple[float, Any]:
    """Worker: :func:`service.runtime.worker.run_part`, and the CPU seconds it took."""
    cpu0 = time.process_time()
    result = run_part(serial, cpu_limit_s, function, *args)
    return time.process_time() - cpu0, result


def part_limit(cpu_limit_s: float) -> tuple[JobBudget | None, float]:
    """The running job's budget and the CPU limit of its next part (:class:`JobBudgetExceeded` when spent)."""
    budget = BUDGET.get()
    return budget, (cpu_limit_s if budget is None else budget.part_limit(cpu_limit_s))


async def charged(
    answer: Awaitable[tuple[float, Any]], budget: JobBudget | None, limit_s: float, cpu_limit_s: float
) -> Any:
    """
    The result of a part run by :func:`run_part_timed` (``answer``), its CPU
    time charged to ``budget``; a part stopped at a limit that was its job's
    budget's (less than ``cpu_limit_s``) raises :class:`JobBudgetExceeded`.
    """
    try:
        cpu_s, result = await answer
    except JobCPULimit:
        if budget is None or limit_s >= cpu_limit_s:
            raise
        budget.charge(limit_s)
        raise JobBudgetExceeded(budget.limit_s, budget.estimate_s) from None
    if budget is not None:
        budget.charge(cpu_s)
    return result


RENDER_BUDGET_FLOOR_S = 2.0
"""A render's budget at least (the first render of a view in a render process also compiles its
program and prefilters its environment: at most 0.45 CPU s more in benchmarks/results/render_cost.json)."""


class RenderTooCostly(ValueError):
    """A render whose estimated CPU seconds pass the CPU-time limit of a job, refused before it starts (422)."""

    def __init__(self, estimate_s: float, limit_s: float) -> None:
        super().__init__(
            f"this render is estimated at {estimate_s:.1f} s of CPU, more than the CPU-time limit of a job, "
            f"{limit_s:g} s (COATED_JOB_CPU_LIMIT_S); ask for a smaller `size` or a smooth view"
        )
        self.estimate_s, self.limit_s = estimate_s, limit_s

    def __reduce__(self):
        return RenderTooCostly, (self.estimate_s, self.limit_s)


class RenderBudgetExceeded(ValueError):
    """A render used its CPU budget and was stopped (422); its render process serves the next one."""

    def __init__(self, budget_s: float, estimate_s: float) -> None:
        super().__init__(
            f"the render used its CPU budget of {budget_s:.1f} s ({BUDGET_FACTOR:g} x its estimated "
            f"{estimate_s:.2f} s, at least {RENDER_BUDGET_FLOOR_S:g} s, at most COATED_JOB_CPU_LIMIT_S) and was "
            "stopped; ask for a smaller `size`"
        )
        self.budget_s, self.estimate_s = budget_s, estimate_s

    def __reduce__(self):
        return RenderBudgetExceeded, (self.budget_s, self.estimate_s)


def render_budget_s(estimate_s: float, cpu_limit_s: float) -> float:
    """
    The CPU seconds a render estimated at ``estimate_s`` may use:
    ``BUDGET_FACTOR x estimate_s``, within [``RENDER_BUDGET_FLOOR_S``,
    ``cpu_limit_s``]; :class:`RenderTooCostly` when the estimate alone
    passes ``cpu_limit_s``.
    """
    if estimate_s > cpu_limit_s:
        raise RenderTooCostly(estimate_s, cpu_limit_s)
    return min(cpu_limit_s, max(RENDER_BUDGET_FLOOR_S, BUDGET_FACTOR * estimate_s))
