"""
benchmarks/stuck_pools.py: a trial's outcome without a kill on either side,
and its arguments' bounds (a killed worker's outcomes are timing's: the
test that kills one while it sends is tests/service/test_faults.py's).
"""

from __future__ import annotations

import asyncio

import pytest

from benchmarks.stuck_pools import SIDES, main, trial


@pytest.mark.slow  # starts worker processes
@pytest.mark.parametrize("side", SIDES)
def test_a_trial_without_a_kill_is_answered(side):
    outcome, seconds = asyncio.run(trial(side, 1 << 20, None, 60.0))
    assert outcome == "answered" and 0 <= seconds < 60


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--trials", "0"], "--trials must lie in [1, 200], got 0"),
        (["--mb", "2000"], "--mb must lie in [1, 1000], got 2000"),
        (["--limit", "0.5"], "--limit must lie in [1, 120], got 0.5"),
        (["--trials", "2.5"], "invalid parse value: '2.5'"),  # a count, not truncated to 2
    ],
)
def test_arguments_out_of_bounds_are_refused(argv, message, capsys):
    with pytest.raises(SystemExit):
        main(argv)
    assert message in capsys.readouterr().err
