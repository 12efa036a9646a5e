"""fitting.domain.BoundedCache: most recently used values by key."""

from __future__ import annotations

import pytest

from fitting.domain import BoundedCache


def test_builds_once_and_drops_the_least_recently_used():
    cache, built = BoundedCache(2), []

    def builder(key):
        def build():
            built.append(key)
            return [key]

        return build

    a = cache.get("a", builder("a"))
    assert cache.get("a", builder("a")) is a and built == ["a"]
    cache.get("b", builder("b"))
    cache.get("a", builder("a"))  # a is now the most recent
    cache.get("c", builder("c"))  # drops b
    assert cache.get("a", builder("a")) is a
    cache.get("b", builder("b"))
    assert built == ["a", "b", "c", "b"]


@pytest.mark.parametrize("size", [0, -1, 1.5])
def test_size_must_be_a_positive_integer(size):
    with pytest.raises(ValueError, match="`size`"):
        BoundedCache(size)


class TestOneFlightPerKey:
    """Concurrent cold gets share one build (the LUT, curve bases, measured curves)."""

    def _race(self, get, threads=8):
        import threading

        barrier, out = threading.Barrier(threads), []

        def run():
            barrier.wait()
            try:
                out.append(get())
            except RuntimeError as error:
                out.append(error)

        workers = [threading.Thread(target=run) for _ in range(threads)]
        for w in workers:
            w.start()
        for w in workers:
            w.join(10)
        return out

    def test_concurrent_gets_share_one_build(self):
        import time

        cache, built = BoundedCache(4), []

        def build():
            built.append(1)
            time.sleep(0.2)
            return object()

        out = self._race(lambda: cache.get("k", build))
        assert len(built) == 1 and len(out) == 8 and all(v is out[0] for v in out)

    def test_a_failed_build_fails_its_waiters_and_is_tried_again_later(self):
        import time

        cache, built = BoundedCache(4), []

        def build():
            built.append(1)
            time.sleep(0.2)
            raise RuntimeError("no")

        out = self._race(lambda: cache.get("k", build))
        assert len(built) == 1 and all(isinstance(v, RuntimeError) for v in out)
        with pytest.raises(RuntimeError):
            cache.get("k", build)
        assert len(built) == 2

    def test_cached_once(self):
        import time

        from fitting.domain import cached_once

        built = []

        @cached_once
        def value():
            """doc"""
            built.append(1)
            time.sleep(0.2)
            return [1]

        out = self._race(value)
        assert len(built) == 1 and all(v is out[0] for v in out) and value.__doc__ == "doc"
