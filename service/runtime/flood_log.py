"""
A flood's warnings, logged once a minute
========================================

The warnings :mod:`service.runtime.server` logs for each connection a
flood makes it close or refuse (:data:`SLOW_CLIENT`, :data:`OVER_BOUND`,
:data:`SLOW_BODY`, and uvicorn's own for its concurrency limit and invalid
requests), and :class:`OncePerInterval`, the logging filter that lets the
first of each through, then one a minute with the count of those dropped,
so that a flood cannot grow the log.
"""

from __future__ import annotations

import logging
import threading
import time

__all__ = ["OncePerInterval", "SLOW_CLIENT", "OVER_BOUND", "SLOW_BODY"]

SLOW_CLIENT = "closed a connection whose request header did not arrive within %g s (COATED_HEADER_TIMEOUT_S)"
OVER_BOUND = (
    "closed a connection past the connection bound that sent no request within %g s "
    "(COATED_MAX_CONNECTIONS, COATED_MAX_CONNECTIONS_PER_CLIENT)"
)
SLOW_BODY = "answered 408 to a request whose body arrived slower than %g bytes per second (COATED_MIN_BODY_RATE)"


class OncePerInterval(logging.Filter):
    """
    Let the first record of each repeated message through, drop the rest
    for ``interval_s``, then let one through with the count of those dropped.
    """

    MESSAGES = ("Exceeded concurrency limit.", "Invalid HTTP request received.", SLOW_CLIENT, OVER_BOUND, SLOW_BODY)

    def __init__(self, interval_s: float = 60.0) -> None:
        super().__init__()
        self.interval_s = interval_s
        self._lock = threading.Lock()
        self._state: dict[str, tuple[float, int]] = {}

    def filter(self, record: logging.LogRecord) -> bool:
        if record.msg not in self.MESSAGES:
            return True
        now = time.monotonic()
        with self._lock:
            last, dropped = self._state.get(record.msg, (-1e18, 0))
            if now - last < self.interval_s:
                self._state[record.msg] = (last, dropped + 1)
                return False
            self._state[record.msg] = (now, 0)
        if dropped:
            record.msg = f"{record.msg} ({dropped} more like it in the last {self.interval_s:g} s)"
        return True
