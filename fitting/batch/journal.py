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
interrupt (the only way a line can be incomplete) is dropped and its page
fitted again.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

__all__ = ["JOURNAL_NAME", "Journal"]

JOURNAL_NAME = "journal.jsonl"
_FORMAT = "fitting-batch-journal/1"


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
        if self.path.exists():
            self._load(header)
        else:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with open(self.path, "w", encoding="utf-8") as f:
                f.write(json.dumps(header, sort_keys=True) + "\n")
                f.flush()
                os.fsync(f.fileno())
        self._file = open(self.path, "a", encoding="utf-8")

    def _load(self, header: dict[str, Any]) -> None:
        data = self.path.read_bytes()
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
        kept = len(lines[0]) + 1
        # Only lines ended by a newline are complete: the last piece is either
        # empty or a record cut short by an interrupt.
        for line in lines[1:-1]:
            try:
                record = json.loads(line)
            except ValueError:
                break
            self.records[record["page"]] = record
            kept += len(line) + 1
        if kept < len(data):
            # Drop the incomplete tail so that new records start on a fresh line.
            with open(self.path, "r+b") as f:
                f.truncate(kept)

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

    def __enter__(self) -> "Journal":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
