"""
Results derived from immutable fits
===================================

A stored fit never changes, so neither does anything computed from it
alone: an export for one format, coating index and roughnesses, a zip of
several fits' exports, a preview. :class:`DerivedCache` keeps such results
(bytes) in memory by key, the least recently used dropped past a bound in
bytes, so that a repeated download costs a lookup instead of its fitting.
Concurrent requests for a key not kept yet share one computation: the
caller's ``make`` is a job of the pool (:meth:`service.runtime.FitRunner.once`,
one flight per key), and its result is kept once it ends.

Each service process keeps its own (replicas each compute a result once);
nothing is kept across restarts.
"""

from __future__ import annotations

import collections
import threading
from collections.abc import Awaitable, Callable, Hashable
from typing import Any

__all__ = ["DerivedCache"]


class DerivedCache:
    """
    Values by key, at most ``max_bytes`` in all (0: nothing kept): bytes, or
    a tuple whose last item is the bytes (what else it holds, such as a
    file name, is counted as nothing); a value larger than a quarter of the
    bound is returned but not kept.
    """

    def __init__(self, max_bytes: int) -> None:
        if max_bytes < 0:
            raise ValueError(f"`max_bytes` must be >= 0, got {max_bytes}")
        self.max_bytes = max_bytes
        self.bytes = 0
        self.hits = self.misses = 0
        self._values: collections.OrderedDict[Hashable, Any] = collections.OrderedDict()
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self._values)

    def get(self, key: Hashable) -> Any:
        """The value kept for ``key`` (now the most recently used), or None."""
        with self._lock:
            value = self._values.get(key)
            if value is None:
                self.misses += 1
                return None
            self._values.move_to_end(key)
            self.hits += 1
            return value

    @staticmethod
    def _size(value: Any) -> int:
        return len(value[-1] if isinstance(value, tuple) else value)

    def put(self, key: Hashable, value: Any) -> None:
        """Keep ``value`` for ``key``, dropping the least recently used past the bound."""
        size = self._size(value)
        if size * 4 > self.max_bytes:
            return
        with self._lock:
            old = self._values.pop(key, None)
            if old is not None:
                self.bytes -= self._size(old)
            self._values[key] = value
            self.bytes += size
            while self.bytes > self.max_bytes:
                _, dropped = self._values.popitem(last=False)
                self.bytes -= self._size(dropped)

    async def get_or_make(self, key: Hashable, make: Callable[[], Awaitable[Any]]) -> Any:
        """The value of ``key``: kept, else ``await make()`` (kept for the next request)."""
        value = self.get(key)
        if value is None:
            value = await make()
            self.put(key, value)
        return value
