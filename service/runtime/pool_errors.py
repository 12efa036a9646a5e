"""
Why the fitting pool did not answer a job
=========================================

The exceptions of :class:`service.runtime.pool.FitRunner` (the HTTP edge
answers 503 with ``Retry-After``, 504 for :class:`FitTimeout`):

-   :class:`Overloaded`: too many jobs in flight.
-   :class:`FitTimeout`: a request waited past the time limit.
-   :class:`WorkerLost`: the job stopped its worker process three times;
    :class:`Quarantined`: such a job's content id, refused for a while.
-   :class:`WorkersNotStarted`: no worker process could be started (not the
    job's doing); :class:`StartFailed`: one start that failed, inside the pool.
"""

from __future__ import annotations

import math
from concurrent.futures.process import BrokenProcessPool

__all__ = ["Overloaded", "FitTimeout", "WorkerLost", "WorkersNotStarted", "StartFailed", "Quarantined"]


class Overloaded(Exception):
    """Too many jobs in flight; ``retry_after`` is a wait estimate in seconds."""

    def __init__(self, retry_after: int, limit: int) -> None:
        super().__init__(
            f"the service is fitting {limit} materials already (the limit); retry in about {retry_after} s"
        )
        self.retry_after = retry_after


class FitTimeout(Exception):
    """A request waited past the time limit; its job goes on and keeps its result."""

    def __init__(self, limit_s: float, retry_after: int = 1) -> None:
        super().__init__(
            f"the fit did not finish within the time limit of {limit_s:g} s (COATED_FIT_TIMEOUT_S); it was cancelled"
        )
        self.retry_after = retry_after


class WorkerLost(Exception):
    """The job's worker process died in the pool twice and then once more alone: the job is the cause."""

    def __init__(self, quarantine_s: float) -> None:
        super().__init__(
            "this job stopped its fitting worker process three times (twice in the pool, then alone); "
            f"it is refused for {quarantine_s:g} s"
        )
        self.retry_after = max(1, math.ceil(quarantine_s))


class WorkersNotStarted(WorkerLost):
    """No worker process could be started, three times (the fork server kept dying): 503, try again."""

    def __init__(self, why: str = "their fork server died") -> None:
        Exception.__init__(self, f"no fitting worker process could be started ({why}); try again")
        self.retry_after = 1


class StartFailed(BrokenProcessPool):
    """
    A pool could not start a worker: its fork server died
    (:data:`service.runtime.fork_server.START_ERRORS`; it has exited since),
    or no fork server or process could be made at all (``why``).
    """

    def __init__(self, why: str | None = None) -> None:
        super().__init__(why or "its fork server died")
        self.why = why

    def not_started(self) -> "WorkersNotStarted":
        """What a job is answered after the last failed start."""
        return WorkersNotStarted() if self.why is None else WorkersNotStarted(self.why)


class Quarantined(WorkerLost):
    """A job whose content id stopped its worker recently is refused before it runs (503)."""

    def __init__(self, left_s: float) -> None:
        Exception.__init__(
            self, f"this job stopped its fitting worker process three times; it is refused for {left_s:.0f} s more"
        )
        self.retry_after = max(1, math.ceil(left_s))
