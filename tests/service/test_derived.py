"""service.derived.DerivedCache: bounded by bytes, least recently used dropped first, one make per miss."""

from __future__ import annotations

import asyncio

import pytest

from service.derived import DerivedCache


def test_bounded_by_bytes_least_recently_used_first():
    cache = DerivedCache(100)
    cache.put("a", b"x" * 20)
    cache.put("b", ("name", b"y" * 20))  # a tuple counts its last item's bytes
    assert cache.bytes == 40
    assert cache.get("a") == b"x" * 20  # "a" is now the most recently used
    cache.put("c", b"z" * 25)
    cache.put("d", b"w" * 25)
    assert cache.bytes == 90 and len(cache) == 4
    cache.put("e", b"v" * 20)  # past 100: "b", the least recently used, goes
    assert cache.get("b") is None and cache.get("a") is not None and cache.bytes == 90
    cache.put("big", b"q" * 26)  # over a quarter of the bound: answered, not kept
    assert cache.get("big") is None
    assert cache.hits == 2 and cache.misses == 2


def test_nothing_kept_at_zero_and_bad_bound():
    cache = DerivedCache(0)
    cache.put("a", b"x")
    assert cache.get("a") is None and cache.bytes == 0
    with pytest.raises(ValueError, match="max_bytes"):
        DerivedCache(-1)


def test_get_or_make_makes_once_then_answers_from_memory():
    cache = DerivedCache(1000)
    made = []

    async def make():
        made.append(1)
        return b"export"

    async def twice():
        return [await cache.get_or_make("k", make), await cache.get_or_make("k", make)]

    assert asyncio.run(twice()) == [b"export", b"export"] and made == [1]
