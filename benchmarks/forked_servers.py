"""
A test server's start: the command against a fork
=================================================

What one server start of the tests costs (tests/conftest.py's
``server_process``: one fit worker, metrics on a 30 x 30 grid, a new data
directory, the pool warmed before the first answer), started as the
command, ``python -m service``, and forked from tests/server_forks.py's
program, which has imported the service once: the wall time from the
start to the first ``/healthz`` answer, and the CPU seconds of the start's
session by then (the server, its fork server, the workers,
multiprocessing's resource tracker; ``benchmarks/server_start.py``'s
reading), in turns (the order swapped every round), after one start of
each not counted. The program's own start (its imports, once a test
process) is recorded beside them.

And what one command run of the tests costs (tests/conftest.py's
``run_command``): :data:`COMMAND`, a fit written to a file, run as the
command, ``python -m fitting``, and forked from the same program, in turns:
its wall seconds and CPU seconds (the command's, read from
``getrusage``'s children; the fork's, from the program's reaped children,
``/proc`` fields ``cutime`` and ``cstime``).

Prints a table and records benchmarks/results/forked_servers.json
(``figures``: per side, the median and max of the wall seconds to ready
and of the CPU seconds in all, and the median CPU seconds per kind of
process; ``program_cpu_s``; ``saved_cpu_s_median``, the command's median
less the fork's; ``commands``: per side the median and max of ``wall_s``
and ``cpu_s``, and ``saved_cpu_s_median``).

Usage: python benchmarks/forked_servers.py [--rounds N]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.server_start import measured, stat_fields, summary  # noqa: E402
from benchmarks.serve import PORT_TAKEN, PORT_TRIES, free_port  # noqa: E402
from benchmarks.suite_time import TICK  # noqa: E402
from server_forks import ServerForks  # noqa: E402

SIDES = ("command", "fork")
ENV = {"COATED_FIT_WORKERS": "1", "COATED_METRICS_SAMPLES": "30"}
"""tests/conftest.py's ``server_process`` defaults."""

COMMAND = ("fit", "Au", "--eta-range", "1:2", "--no-metrics", "-o")
"""The command run (``python -m fitting``, then the output file): a fit of the CLI's tests."""


def start(side: str, forks: ServerForks) -> dict:
    """One start: seconds to the first answer and CPU seconds per kind of the start's session by then."""
    env = {**os.environ, **ENV}
    for attempt in range(PORT_TRIES):
        port = free_port()
        with tempfile.TemporaryDirectory() as data:
            argv = ["--host", "127.0.0.1", "--port", str(port), "--data-dir", f"{data}/data"]
            log = Path(data) / "log"
            t0 = time.monotonic()
            if side == "fork":
                process = forks.start(argv, env, log)
            else:
                with open(log, "wb") as out:
                    process = subprocess.Popen(
                        [sys.executable, "-m", "service", *argv],
                        cwd=ROOT,
                        env=env,
                        stdout=out,
                        stderr=subprocess.STDOUT,
                        start_new_session=True,
                    )
            try:
                return measured(
                    process, port, t0, f"the {side}'s server", lambda: log.read_text(errors="replace")[-4000:]
                )
            except RuntimeError:
                if attempt + 1 == PORT_TRIES or PORT_TAKEN not in log.read_text(errors="replace"):
                    raise
    raise AssertionError("unreachable")


def run_command(side: str, forks: ServerForks) -> dict:
    """One ``python -m fitting`` run of :data:`COMMAND`: its wall and CPU seconds."""
    with tempfile.TemporaryDirectory() as directory:
        argv = [*COMMAND, f"{directory}/au.cfpk"]
        if side == "fork":
            before = program_cpu(forks, reaped=True) if forks.running() else 0.0  # it starts with the first fork
            t0 = time.monotonic()
            result = forks.run("fitting", argv, dict(os.environ), ROOT, timeout=300)
            wall = time.monotonic() - t0
            cpu = program_cpu(forks, reaped=True) - before
        else:
            usage = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.monotonic()
            result = subprocess.run(
                [sys.executable, "-m", "fitting", *argv], cwd=ROOT, capture_output=True, text=True, timeout=300
            )
            wall = time.monotonic() - t0
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = after.ru_utime + after.ru_stime - usage.ru_utime - usage.ru_stime
        if result.returncode != 0:
            raise RuntimeError(f"the {side}'s python -m fitting exited with {result.returncode}: {result.stderr}")
    return {"wall_s": wall, "cpu_s": cpu}


def program_cpu(forks: ServerForks, reaped: bool = False) -> float:
    """
    CPU seconds the forks' program has spent (its imports; its requests cost
    next to nothing), or with ``reaped`` those of its reaped children, its
    forks (``/proc`` fields ``cutime`` and ``cstime``).
    """
    fields = stat_fields(forks.program.pid)
    first = 13 if reaped else 11
    return (int(fields[first]) + int(fields[first + 1])) / TICK


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=10, help="counted starts of each side (default 10)")
    args = parser.parse_args(argv)
    if not 1 <= args.rounds <= 100:
        parser.error(f"--rounds must lie in [1, 100], got {args.rounds}")
    load = load_average()
    forks = ServerForks()
    try:
        for side in SIDES:
            start(side, forks)  # the program's start and the bytecode caches, not counted
        program = program_cpu(forks)
        runs = {side: [] for side in SIDES}
        for i in range(args.rounds):
            for side in SIDES if i % 2 == 0 else SIDES[::-1]:
                runs[side].append(start(side, forks))
        for side in SIDES:
            run_command(side, forks)  # not counted
        commands = {side: [] for side in SIDES}
        for i in range(args.rounds):
            for side in SIDES if i % 2 == 0 else SIDES[::-1]:
                commands[side].append(run_command(side, forks))
    finally:
        forks.close()
    figures = {side: summary(runs[side]) for side in SIDES}
    figures["program_cpu_s"] = program
    figures["saved_cpu_s_median"] = figures["command"]["cpu_s"]["median"] - figures["fork"]["cpu_s"]["median"]
    figures["commands"] = {
        side: {
            key: {
                "median": statistics.median(r[key] for r in commands[side]),
                "max": max(r[key] for r in commands[side]),
            }
            for key in ("wall_s", "cpu_s")
        }
        for side in SIDES
    }
    figures["commands"]["saved_cpu_s_median"] = (
        figures["commands"]["command"]["cpu_s"]["median"] - figures["commands"]["fork"]["cpu_s"]["median"]
    )
    kinds = sorted({k for side in SIDES for k in figures[side]["cpu_s_median_by_kind"]})
    print(f"a test server's start, {args.rounds} of each side ({', '.join(f'{k}={v}' for k, v in ENV.items())})")
    print(f"{'':<36}{'command':>10}{'fork':>10}")
    for label, key in (
        ("ready s, median", ("ready_s", "median")),
        ("ready s, max", ("ready_s", "max")),
        ("CPU s, median", ("cpu_s", "median")),
        ("CPU s, max", ("cpu_s", "max")),
    ):
        print(f"{label:<36}" + "".join(f"{figures[s][key[0]][key[1]]:>10.2f}" for s in SIDES))
    for kind in kinds:
        print(
            f"{'  CPU s, ' + kind + ', median':<36}"
            + "".join(f"{figures[s]['cpu_s_median_by_kind'].get(kind, 0.0):>10.2f}" for s in SIDES)
        )
    print(
        f"saved a start (medians): {figures['saved_cpu_s_median']:.2f} CPU s; "
        f"the program's own start, once a test process: {program:.2f} CPU s"
    )
    print(f"\na command run of the tests, python -m fitting {' '.join(COMMAND)} FILE, {args.rounds} of each side")
    print(f"{'':<36}{'command':>10}{'fork':>10}")
    for label, key in (
        ("wall s, median", ("wall_s", "median")),
        ("wall s, max", ("wall_s", "max")),
        ("CPU s, median", ("cpu_s", "median")),
        ("CPU s, max", ("cpu_s", "max")),
    ):
        print(f"{label:<36}" + "".join(f"{figures['commands'][s][key[0]][key[1]]:>10.2f}" for s in SIDES))
    print(f"saved a run (medians): {figures['commands']['saved_cpu_s_median']:.2f} CPU s")
    write_result("forked_servers", figures, load, rounds=args.rounds, runs=runs, commands=commands)
    return 0


if __name__ == "__main__":
    sys.exit(main())
