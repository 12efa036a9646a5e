"""
:func:`at_once`: one call from many threads released together, for the
tests of what concurrent callers share (service.store.shared_check, the
PostgreSQL store's connection check).
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable


def at_once(call: Callable[[], Any], n: int = 8) -> list:
    """``call()`` from ``n`` threads released by one barrier: each one's result, or the exception it raised."""
    barrier = threading.Barrier(n)

    def one(_):
        barrier.wait()
        try:
            return call()
        except Exception as error:  # noqa: BLE001 (each caller's outcome is what the tests check)
            return error

    with ThreadPoolExecutor(n) as pool:
        return list(pool.map(one, range(n)))
