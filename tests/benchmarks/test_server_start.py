"""
benchmarks/server_start.py: the processes of a start counted by kind (the
server, its fork server, whatever its command line, the workers, the
resource tracker), a real start of this checkout measured, and its
arguments' bounds.
"""

from __future__ import annotations

import pytest

from benchmarks.server_start import ROOT, by_kind, kind_of, main, start

SERVER = "/r/.venv/bin/python -m service --port 40123 --data-dir /tmp/x"
TRACKER = "/r/.venv/bin/python -B -c from multiprocessing.resource_tracker import main;main(15)"
FORK_SERVER = (
    "/r/.venv/bin/python -B -c from multiprocessing.forkserver import main; main(18, 19, ['service.runtime.preload'])"
)


def test_kinds_by_command_line():
    assert kind_of(TRACKER) == "resource_tracker"
    assert kind_of(FORK_SERVER) == "fork_server"
    assert kind_of(SERVER) == "server"


@pytest.mark.parametrize("fork_server_command", [FORK_SERVER, SERVER])  # a new interpreter, or a fork
def test_a_start_s_processes_by_kind(fork_server_command):
    processes = {
        10: (1, SERVER, 2.0),
        11: (10, TRACKER, 0.03),
        12: (10, fork_server_command, 1.25),
        13: (12, fork_server_command, 0.125),
        14: (12, fork_server_command, 0.25),
    }
    assert by_kind(processes, 10) == {"server": 2.0, "resource_tracker": 0.03, "fork_server": 1.25, "workers": 0.375}


@pytest.mark.slow  # starts a server
def test_a_start_of_this_checkout_is_measured():
    run = start(ROOT, 1)
    assert run["ready_s"] > 0
    # The server, its fork server (a fork of it: start_fork_server), two workers (one and the express one).
    assert set(run["kinds"]) == {"server", "fork_server", "workers", "resource_tracker"}
    assert run["kinds"]["server"] > 0 and run["cpu_s"] == pytest.approx(sum(run["kinds"].values()))


@pytest.mark.slow  # starts servers
def test_a_start_whose_port_was_taken_is_tried_again_on_another(monkeypatch):
    """A port taken between free_port() and the bind ("address already in use"): tried again on another."""
    from ports import taken_first

    import benchmarks.server_start as server_start

    with taken_first(monkeypatch, server_start, "free_port") as (_, first):
        run = start(ROOT, 1)
    assert run["ready_s"] > 0 and not first


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--rounds", "0"], "--rounds must lie in [1, 100], got 0"),
        (["--workers", "17"], "--workers must lie in [1, 16], got 17"),
    ],
)
def test_arguments_out_of_bounds_are_refused(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err
