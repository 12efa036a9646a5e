"""
Batch journal
=============

-   :class:`Journal`: the append-only record of finished pages in a batch's
    output directory (``journal.jsonl``), which makes a batch resumable.

The first line holds the batch's configuration; every further line one
page's finished record, written and flushed to disk (``fsync``) before the
page counts as done. A batch started again over the same directory reads the
journal, keeps every complete record and fits only the pages without one:
nothing is fitted twice and nothing finished is lost. A line cut short by an
interrupt is dropped and its page fitted again; a damaged line anywhere else
(not JSON, or JSON but not a page's record) is skipped, and every valid
record before and after it is kept.

The journal holds an exclusive lock on the directory (``flock`` on
``.lock``) while it is open: a second batch on the same directory is
refused at once instead of fitting every page again beside the first. The
journal and the lock file are opened with ``O_NOFOLLOW`` and
``O_NONBLOCK``, and must be regular files: a link planted under their names
is refused, never written through, and a FIFO or a device is refused
instead of hanging the batch. A journal larger than
:data:`MAX_JOURNAL_BYTES` is refused before a byte of it is read.
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
import stat
from pathlib import Path
from typing import Any

__all__ = ["JOURNAL_NAME", "LOCK_NAME", "MAX_JOURNAL_BYTES", "Journal"]

JOURNAL_NAME = "journal.jsonl"
LOCK_NAME = ".lock"
_FORMAT = "fitting-batch-journal/1"

MAX_JOURNAL_BYTES = 256 * 2**20
"""The largest journal a batch reads (256 MiB; a page's record is about 1-3 kB, so some 100,000 pages)."""


class Journal:
    """
    The journal of a batch in ``directory`` for ``config`` (a JSON-ready
    dict: selection, kinds, settings).

    ``records`` maps each finished page to its record. Opening a directory
    whose journal was written for another configuration raises
    ``ValueError``, so that a resumed batch never mixes settings.
    """

    def __init__(self, directory: str | Path, config: dict[str, Any]) -> None:
        self.path = Path(directory) / JOURNAL_NAME
        self.config = config
        self.records: dict[str, dict[str, Any]] = {}
        header = {"format": _FORMAT, "config": config}
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._lock = _lock_directory(self.path.parent)
        try:
            try:
                fd = _open_nofollow(self.path, os.O_RDWR | os.O_APPEND)
            except FileNotFoundError:
                fd = _open_nofollow(self.path, os.O_RDWR | os.O_APPEND | os.O_CREAT | os.O_EXCL)
                os.write(fd, (json.dumps(header, sort_keys=True) + "\n").encode("utf-8"))
                os.fsync(fd)
            else:
                self._load(fd, header)
            self._file = os.fdopen(fd, "a", encoding="utf-8")
        except BaseException:
            os.close(self._lock)
            raise

    def _load(self, fd: int, header: dict[str, Any]) -> None:
        size = os.fstat(fd).st_size
        if size > MAX_JOURNAL_BYTES:
            raise ValueError(
                f"`output` {self.path} holds {size} bytes, more than a batch journal may "
                f"({MAX_JOURNAL_BYTES}); choose another output directory"
            )
        with os.fdopen(os.dup(fd), "rb") as f:
            data = f.read()
        lines = data.split(b"\n")
        try:
            found = json.loads(lines[0])
        except ValueError:
            raise ValueError(f"`output` {self.path} is not a batch journal") from None
        if found != json.loads(json.dumps(header)):
            raise ValueError(
                f"`output` {self.path.parent} holds the journal of a different batch "
                "(other selection, model kinds or settings); choose another output directory"
            )
        # Only lines ended by a newline are complete: the last piece is either
        # empty or a record cut short by an interrupt.
        for line in lines[1:-1]:
            try:
                record = json.loads(line)
            except ValueError:
                continue  # a torn line: the records around it stand
            if isinstance(record, dict) and isinstance(record.get("page"), str):
                self.records.setdefault(record["page"], record)
        if lines[-1]:
            # Drop the incomplete tail so that new records start on a fresh line.
            os.ftruncate(fd, len(data) - len(lines[-1]))

    def append(self, record: dict[str, Any]) -> None:
        """Write one finished page durably; a page already journaled is ignored."""
        if record["page"] in self.records:
            return
        self._file.write(json.dumps(record, sort_keys=True) + "\n")
        self._file.flush()
        os.fsync(self._file.fileno())
        self.records[record["page"]] = record

    def close(self) -> None:
        self._file.close()
        os.close(self._lock)  # and the lock with it

    def __enter__(self) -> "Journal":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _open_nofollow(path: Path, flags: int) -> int:
    """
    ``os.open`` of a regular file that refuses a link at ``path``, and a
    FIFO, socket or device (opened without blocking, then checked):
    ``ValueError`` naming it.
    """
    try:
        fd = os.open(path, flags | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK, 0o644)
    except OSError as error:
        if error.errno == errno.ELOOP:
            raise ValueError(f"`output` {path} is a symbolic link; a batch writes only its own files") from None
        if error.errno == errno.ENXIO:  # a FIFO without a reader, opened for writing
            raise ValueError(
                f"`output` {path} is not a regular file (a FIFO); a batch opens only its own files"
            ) from None
        raise
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        kind = (
            "a FIFO"
            if stat.S_ISFIFO(mode)
            else "a device"
            if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
            else ("a directory" if stat.S_ISDIR(mode) else "a socket or other special file")
        )
        raise ValueError(f"`output` {path} is not a regular file ({kind}); a batch opens only its own files")
    os.set_blocking(fd, True)
    return fd


def _lock_directory(directory: Path) -> int:
    """An exclusive ``flock`` on ``directory/.lock`` (its descriptor), or ``ValueError`` if taken."""
    fd = _open_nofollow(directory / LOCK_NAME, os.O_RDWR | os.O_CREAT)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise ValueError(
            f"`output` {directory} is in use by another batch run; wait for it or choose another directory"
        ) from None
    return fd
