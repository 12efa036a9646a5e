"""
benchmarks/forked_servers.py: one start of each side read from its
session (the server and its warmed pool's worker), one command run of each
side read from its CPU time, and its arguments' bounds.
"""

from __future__ import annotations

import pytest
from conftest import SERVER_FORKS
from server_forks import ServerForks

from benchmarks.forked_servers import SIDES, main, run_command, start

pytestmark = [pytest.mark.server, pytest.mark.slow]


def test_a_start_of_each_side_is_read_from_its_session():
    forks = ServerForks()
    try:
        for side in SIDES:
            run = start(side, forks)
            assert run["ready_s"] > 0, (side, run)
            assert run["kinds"]["server"] > 0 and run["kinds"]["workers"] > 0, (side, run)  # the pool is warmed
            assert run["cpu_s"] == pytest.approx(sum(run["kinds"].values())), (side, run)
    finally:
        forks.close()
    assert forks.program is None


def test_a_command_run_of_each_side_is_read_from_its_cpu_time():
    # The test process's own program (started here if no test before started it), as the command tests use.
    runs = {side: run_command(side, SERVER_FORKS) for side in SIDES}
    for side, run in runs.items():
        assert 0 < run["cpu_s"] < 60 and 0 < run["wall_s"] < 300, (side, run)
    # The command imports the core (over half a CPU second here); the fork inherits it.
    assert runs["fork"]["cpu_s"] < runs["command"]["cpu_s"], runs


@pytest.mark.parametrize("rounds", ["0", "101"])
def test_the_forked_servers_benchmark_refuses_rounds_out_of_bounds(rounds, capsys):
    with pytest.raises(SystemExit):
        main(["--rounds", rounds])
    assert f"--rounds must lie in [1, 100], got {rounds}" in capsys.readouterr().err
