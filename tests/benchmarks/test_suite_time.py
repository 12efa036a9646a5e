"""
benchmarks/suite_time.py: the side-by-side mode runs what ``scripts/test``
runs for the full suite, its memory calibration takes time, its
arguments' bounds, and a record's median and worst run of each mode.
"""

from __future__ import annotations

import pytest

from benchmarks.suite_time import COMPILED, FULL_SUITE, ROOT, main, memory_calibration, mode_figures, mode_name


def test_the_side_by_side_runs_scripts_test_s_full_suite():
    script = (ROOT / "scripts" / "test").read_text()
    assert f'"$py" {" ".join(FULL_SUITE)}\n' in script
    assert f'"$py" -m compileall -q {" ".join(COMPILED)} >/dev/null\n' in script


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--rounds", "0"], "--rounds must lie in [1, 5], got 0"),
        (
            ["--name", "../suite_time"],
            "--name must be suite_time_ and lower-case letters, digits or _, got '../suite_time'",
        ),
        pytest.param(
            ["--before", "no-such-commit"],
            "--before must name a commit of this repository, got 'no-such-commit'",
            marks=pytest.mark.slow,
        ),  # asks git
    ],
)
def test_arguments_out_of_bounds_are_refused(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err


def test_the_memory_calibration_takes_cpu_time():
    assert 0.0 < memory_calibration(rounds=1) < 60.0  # the record takes the best of 3 of the same copies


def test_each_mode_s_median_and_worst_run():
    rows = [
        {"mode": mode_name(args), "seconds": seconds, "returncode": code}
        for args, seconds, code in [
            (["--quick"], 50.0, 0),
            ([], 300.0, 0),
            (["--quick"], 61.0, 0),
            ([], 380.0, 1),
            (["--quick"], 52.0, 0),
            ([], 310.0, 0),
            (["--other-cpus"], 190.0, 0),
        ]
    ]
    figures = mode_figures(rows)
    assert list(figures) == ["quick", "full", "other-cpus"]
    assert figures["quick"] == {"runs": 3, "median_s": 52.0, "worst_s": 61.0, "all_passed": True}
    assert figures["full"] == {"runs": 3, "median_s": 310.0, "worst_s": 380.0, "all_passed": False}
    assert figures["other-cpus"] == {"runs": 1, "median_s": 190.0, "worst_s": 190.0, "all_passed": True}
