"""The on-disk cache of the split-sum LUT (fitting.shading.ibl.cached_lut)."""

from __future__ import annotations

import os

import numpy as np
import pytest

from fitting.shading import lut as ibl
from fitting.shading.lut import cached_lut, decode_lut, encode_lut, generate_lut, lut_cache_path

SMALL = dict(shape=(3, 4, 5), alpha_range=(0.5, 12.0), samples=64)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(ibl.CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


def test_first_call_writes_identical_bytes(cache):
    lut = cached_lut(**SMALL)
    path = lut_cache_path(**SMALL)
    assert path.parent == cache and path.is_file()
    fresh = generate_lut(**SMALL)
    assert path.read_bytes() == encode_lut(fresh)
    assert lut.data.tobytes() == fresh.data.tobytes()
    assert [p.name for p in cache.iterdir()] == [path.name]  # no temporary left


def test_second_call_reads_the_file(cache, monkeypatch):
    first = cached_lut(**SMALL)

    def fail(*args, **kwargs):
        raise AssertionError("regenerated despite a valid cache file")

    monkeypatch.setattr(ibl, "generate_lut", fail)
    second = cached_lut(**SMALL)
    assert second.data.tobytes() == first.data.tobytes()
    assert second.alpha_range == first.alpha_range


def test_key_changes_with_every_parameter(cache):
    base = lut_cache_path(**SMALL)
    assert lut_cache_path(**{**SMALL, "samples": 128}) != base
    assert lut_cache_path(**{**SMALL, "shape": (3, 4, 6)}) != base
    assert lut_cache_path(**{**SMALL, "alpha_range": (0.5, 11.0)}) != base
    assert f"v{ibl.CACHE_FORMAT_VERSION}_" in base.name


def test_damaged_file_is_regenerated(cache):
    cached_lut(**SMALL)
    path = lut_cache_path(**SMALL)
    blob = bytearray(path.read_bytes())
    blob[100] ^= 0xFF
    path.write_bytes(bytes(blob))
    with pytest.raises(ValueError, match="CRC"):
        decode_lut(bytes(blob))
    lut = cached_lut(**SMALL)
    assert path.read_bytes() == encode_lut(generate_lut(**SMALL))
    assert np.all(np.isfinite(lut.data))


def test_unwritable_cache_still_returns_the_lut(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv(ibl.CACHE_ENV, str(blocker / "cache"))
    lut = cached_lut(**SMALL)
    assert lut.data.tobytes() == generate_lut(**SMALL).data.tobytes()
    assert not os.path.exists(blocker / "cache")
