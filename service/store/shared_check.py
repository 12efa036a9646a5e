"""
One check at a time, shared
===========================

:class:`SharedCheck`: runs a check (a callable that returns nothing or
raises) for one caller at a time; callers that come while it runs wait for
it and take its outcome, returning or raising an error of the same class
and message, instead of running it again. The PostgreSQL store's check
whether a server that went away is back (one plain connection) is one: a
burst of calls then opens one connection, not one each.
"""

from __future__ import annotations

import threading
from typing import Callable

__all__ = ["SharedCheck"]


class _Run:
    """One run of the check: done when it ends; its error, if it raised one of the expected class."""

    def __init__(self, unfinished: Exception) -> None:
        self.done = threading.Event()
        self.error: Exception | None = unfinished


def _copy(error: Exception, fallback: type[Exception]) -> Exception:
    """An error of the same class and message, for another thread to raise (each caller raises its own)."""
    try:
        return type(error)(*error.args)
    except TypeError:
        return fallback(str(error))


class SharedCheck:
    """
    ``check()`` for one caller at a time: :meth:`__call__` runs it, or,
    while another caller's run is in flight, waits for that run (at most
    ``wait_s``) and takes its outcome. ``errors`` is the class of the
    errors shared (a caller whose wait ends first raises one, with a message
    saying so); any other exception reaches only the caller that ran it,
    and its followers raise ``errors`` too.
    """

    def __init__(self, check: Callable[[], None], errors: type[Exception], wait_s: float) -> None:
        self._check, self._errors, self._wait_s = check, errors, float(wait_s)
        self._lock = threading.Lock()  # guards _in_flight
        self._in_flight: _Run | None = None

    def __call__(self) -> None:
        with self._lock:
            run, leader = self._in_flight, False
            if run is None:
                run, leader = _Run(self._errors("the check of another call did not finish")), True
                self._in_flight = run
        if not leader:
            if not run.done.wait(self._wait_s):
                raise self._errors(f"no outcome of another call's check within {self._wait_s:g} s")
            if run.error is not None:
                raise _copy(run.error, self._errors)
            return
        try:
            self._check()
            run.error = None
        except self._errors as error:
            run.error = error
            raise
        finally:
            with self._lock:
                self._in_flight = None
            run.done.set()
