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
