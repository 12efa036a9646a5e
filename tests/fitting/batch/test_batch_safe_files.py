"""
A batch writes only its own files in its output directory
(links planted under its temporary or output names are never written
through), refuses a FIFO planted at its journal or lock and a journal past
its size (before reading it), holds the directory against a second run,
and keeps every valid journal record around a damaged line.
"""

from __future__ import annotations

import json
import os

import pytest

from fitting.batch import OUTPUT_FILES, run_batch
from fitting.batch.journal import JOURNAL_NAME, Journal

PAGE = "main/Au/Johnson"
SAMPLES = 30


def plant(directory, victim):
    """Links to ``victim`` under every name a batch wrote or writes through, and the outputs' own names."""
    directory.mkdir(parents=True, exist_ok=True)
    for name in OUTPUT_FILES:
        os.symlink(victim, directory / f"{name}.tmp")
    os.symlink(victim, directory / "report.csv")


@pytest.mark.slow
def test_planted_links_are_never_written_through(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    out = tmp_path / "out"
    plant(out, victim)
    run_batch([PAGE], out, workers=1, samples=SAMPLES, progress=False)
    assert victim.read_text() == "precious\n"
    assert not (out / "report.csv").is_symlink() and "main/Au/Johnson" in (out / "report.csv").read_text()
    leftovers = [p.name for p in out.iterdir() if p.name.endswith(".tmp") and not p.is_symlink()]
    assert leftovers == []


def test_a_journal_link_is_refused(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    out = tmp_path / "out"
    out.mkdir()
    os.symlink(victim, out / JOURNAL_NAME)
    with pytest.raises(ValueError, match="is a symbolic link"):
        run_batch([PAGE], out, workers=1, samples=SAMPLES, progress=False)
    assert victim.read_text() == "precious\n"


@pytest.mark.parametrize("name", [JOURNAL_NAME, ".lock"])
def test_a_fifo_planted_at_the_journal_or_lock_is_refused_not_waited_on(tmp_path, name):
    os.mkfifo(tmp_path / name)
    with pytest.raises(ValueError, match=r"is not a regular file \(a FIFO\)"):
        Journal(tmp_path, {"pages": [PAGE]})


def test_a_journal_past_its_size_is_refused_before_it_is_read(tmp_path):
    with open(tmp_path / JOURNAL_NAME, "wb") as f:
        f.truncate(2**30)  # 1 GB, sparse: read whole, it took 1.39 GB of memory
    with pytest.raises(ValueError, match=f"holds {2**30} bytes, more than a batch journal may"):
        Journal(tmp_path, {"pages": [PAGE]})


def test_a_second_run_on_one_directory_is_refused(tmp_path):
    config = {"pages": [PAGE]}
    with Journal(tmp_path, config):
        with pytest.raises(ValueError, match="in use by another batch run"):
            Journal(tmp_path, config)
    Journal(tmp_path, config).close()  # free again once the first is closed


@pytest.mark.parametrize(
    "damage",
    [
        '{"page": "b", "status": "fit',  # torn mid-file
        "[1, 2, 3]",  # JSON, not an object
        '"text"',
        '{"no": "page"}',
        '{"page": 7}',
        "\x00\x00garbage",
    ],
)
def test_every_valid_record_around_a_damaged_line_is_kept(tmp_path, damage):
    config = {"pages": ["a", "c"]}
    with Journal(tmp_path, config) as journal:
        journal.append({"page": "a", "status": "fitted"})
    with open(tmp_path / JOURNAL_NAME, "a") as f:
        f.write(damage + "\n" + json.dumps({"page": "c", "status": "fitted"}) + "\n")
    with Journal(tmp_path, config) as journal:
        assert sorted(journal.records) == ["a", "c"]
        journal.append({"page": "d", "status": "fitted"})
    with Journal(tmp_path, config) as journal:
        assert sorted(journal.records) == ["a", "c", "d"]
