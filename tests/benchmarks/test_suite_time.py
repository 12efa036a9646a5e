"""
benchmarks/suite_time.py: the side-by-side mode runs what ``scripts/test``
runs for the full suite, its memory calibration takes time, and its
arguments' bounds.
"""

from __future__ import annotations

import pytest

from benchmarks.suite_time import COMPILED, FULL_SUITE, ROOT, main, memory_calibration


def test_the_side_by_side_runs_scripts_test_s_full_suite():
    script = (ROOT / "scripts" / "test").read_text()
    assert f'"$py" {" ".join(FULL_SUITE)}\n' in script
    assert f'"$py" -m compileall -q -j 0 {" ".join(COMPILED)} >/dev/null\n' in script


@pytest.mark.parametrize("argv, message", [
    (["--rounds", "0"], "--rounds must lie in [1, 5], got 0"),
    (["--name", "../suite_time"], "--name must be suite_time_ and lower-case letters, digits or _, got '../suite_time'"),
    pytest.param(["--before", "no-such-commit"], "--before must name a commit of this repository, got 'no-such-commit'",
                 marks=pytest.mark.slow),  # asks git
])
def test_arguments_out_of_bounds_are_refused(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err


def test_the_memory_calibration_takes_cpu_time():
    assert 0.0 < memory_calibration() < 60.0
