"""
benchmarks/browser_page_cost.py: its arguments' bounds (a load read by
kind of process is tested with the browser tests' Chromium,
tests/static/test_chromium_launch.py).
"""

from __future__ import annotations

import pytest

from benchmarks.browser_page_cost import main


@pytest.mark.parametrize("rounds", ["0", "101"])
def test_the_page_cost_benchmark_refuses_rounds_out_of_bounds(rounds, capsys):
    with pytest.raises(SystemExit):
        main(["--rounds", rounds])
    assert f"--rounds must lie in [1, 100], got {rounds}" in capsys.readouterr().err
