"""benchmarks/curve_guard_phases.py: a refit's CPU split by the guard's phases, the guard left as it was."""

from __future__ import annotations

import json
from collections import Counter

import pytest

import benchmarks.record as record
import fitting.fits.curves_guard as guard
from benchmarks import curve_guard_phases


@pytest.mark.slow  # two guarded refits with the minimax, about 6 s
def test_the_phases_add_up_and_the_guard_is_restored(tmp_path, monkeypatch):
    monkeypatch.setattr(record, "RESULTS", tmp_path)
    before = {name: getattr(guard, name) for name in curve_guard_phases.PHASES}
    assert curve_guard_phases.main(["--rounds", "1", "--edits", "Au red pulled to 0.1"]) == 0
    assert {name: getattr(guard, name) for name in curve_guard_phases.PHASES} == before
    saved = json.loads((tmp_path / "curve_guard_phases.json").read_text())
    (row,) = saved["rows"]
    phases = [row[f"{p}_s"] for p in (*curve_guard_phases.PHASES.values(), "rest")]
    assert row["minimax_ran"] and row["auditors_s"] > 0 and all(p >= 0 for p in phases)
    assert sum(phases) == pytest.approx(row["total_s"], abs=1e-3)
    assert saved["figures"]["with_minimax"]["edits"] == 1 and saved["figures"]["without_minimax"]["edits"] == 0


def test_a_timed_phase_counts_a_generator_as_it_is_consumed():
    class Guard:
        @staticmethod
        def minimax_fit():
            yield from range(3)

        auditor_fits = constrained_refits = polish_float16 = staticmethod(lambda: 7)

    with curve_guard_phases.timed_phases(Guard) as spent:
        assert Guard.minimax_fit() == [0, 1, 2] and Guard.auditor_fits() == 7
    assert isinstance(spent, Counter) and set(spent) == {"minimax", "auditors"}
    assert list(Guard.minimax_fit()) == [0, 1, 2] and not isinstance(Guard.minimax_fit(), list)
