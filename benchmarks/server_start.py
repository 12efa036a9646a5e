"""
A server start against an earlier commit
========================================

What starting ``python -m service`` costs, with the defaults (the
SQLite store in a new directory, the fitting pool warmed before the first
answer): the wall time from the start to the first ``/healthz`` answer, and
the CPU seconds of every process of the start by then (the server, its
fork server, the workers, multiprocessing's resource tracker; read from
``/proc`` once the server answers, the process and what it reaped), in a
checkout of ``--before`` (by default 9e06edd, the last commit whose fork
server was a new interpreter importing the core again) and in this
checkout, in turns (the order swapped every round, so that the machine's
drifting load lands on both alike), after one start of each not counted
(it writes the checkout's bytecode caches).

Prints a table and records benchmarks/results/server_start.json
(``figures``: per side, the median and max of the wall seconds to ready
and of the CPU seconds in all, and the median CPU seconds per kind of
process; ``ratio_cpu_median`` and ``ratio_ready_median``, this checkout's
over the earlier one's).

Usage: python benchmarks/server_start.py [--before REV] [--rounds N] [--workers N]
"""

from __future__ import annotations

import argparse
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import Iterator

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.serve import PORT_TAKEN, PORT_TRIES, free_port  # noqa: E402  (the start's retry rule)
from benchmarks.side_by_side import checkout  # noqa: E402
from benchmarks.suite_time import TICK  # noqa: E402

BEFORE = "9e06edd"
"""The last commit whose fork server was a new interpreter (``python -c 'from multiprocessing.forkserver ...'``)."""

READY_TIMEOUT_S = 120.0


def _answers(port: int) -> bool:
    """``GET /healthz`` answered 200 (plain HTTP over a socket, so that this process imports no client)."""
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=2.0) as sock:
            sock.sendall(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")
            return sock.recv(64).startswith(b"HTTP/1.1 200")
    except OSError:
        return False


def kind_of(command: str) -> str:
    """The kind of a process of a start, by its command line."""
    if "multiprocessing.resource_tracker" in command:
        return "resource_tracker"
    if "multiprocessing.forkserver" in command:
        return "fork_server"
    return "server"


def stat_fields(pid: int | str) -> list[str]:
    """
    The fields of ``/proc/PID/stat`` after the command name (``[1]`` parent,
    ``[3]`` session, ``[11:13]`` user and system ticks, ``[13:15]`` its
    reaped children's, ``[19]`` start time); ``OSError`` once it is gone.
    """
    stat = Path(f"/proc/{pid}/stat").read_text()
    return stat[stat.rfind(")") + 2 :].split()


def processes() -> Iterator[tuple[int, list[str], str]]:
    """Every live process: its pid, its :func:`stat_fields` and its command line."""
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            fields = stat_fields(pid)
            command = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        yield int(pid), fields, command


def session_cpu(session: int) -> dict[int, tuple[int, str, float]]:
    """Every live process of ``session``: pid -> (parent pid, command line, CPU seconds with its reaped children)."""
    return {
        pid: (int(fields[1]), command, sum(int(f) for f in fields[11:15]) / TICK)
        for pid, fields, command in processes()
        if int(fields[3]) == session
    }


def by_kind(processes: dict[int, tuple[int, str, float]], server: int) -> Counter:
    """CPU seconds per kind: the server, the fork server (a child with children), its workers, the tracker."""
    kinds = Counter()
    parents = {parent for parent, _, _ in processes.values()}
    for pid, (parent, command, seconds) in processes.items():
        if pid == server:
            kinds["server"] += seconds
        elif parent == server:
            kinds["fork_server" if pid in parents else kind_of(command)] += seconds
        else:
            kinds["workers"] += seconds
    return kinds


def start(root: Path, workers: int | None) -> dict:
    """One start of ``root``'s service: seconds to the first answer and CPU seconds per kind by then."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    if workers is not None:
        env["COATED_FIT_WORKERS"] = str(workers)
    for attempt in range(PORT_TRIES):
        port = free_port()
        with tempfile.TemporaryDirectory() as data:
            t0 = time.monotonic()
            process = subprocess.Popen(
                [sys.executable, "-m", "service", "--port", str(port), "--data-dir", data],
                cwd=root,
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                start_new_session=True,
            )
            try:
                return measured(
                    process,
                    port,
                    t0,
                    f"the server of {root}",
                    lambda: process.stderr.read().decode(errors="replace")[-2000:],
                )
            except RuntimeError as error:
                if attempt + 1 == PORT_TRIES or PORT_TAKEN not in str(error):
                    raise
    raise AssertionError("unreachable")


def measured(process, port: int, t0: float, what: str, output=lambda: "") -> dict:
    """
    Wait for ``process``'s first ``/healthz`` answer on ``port``; the seconds
    since ``t0`` and the CPU seconds per kind of its session by then; stop
    it. ``process`` is a ``subprocess.Popen`` or tests/server_forks.py's
    ``ForkedProcess``; ``output()``, what it wrote, names an early exit.
    """
    try:
        while not _answers(port):
            if process.poll() is not None:
                raise RuntimeError(f"{what} exited ({process.returncode}): {output()}")
            if time.monotonic() - t0 > READY_TIMEOUT_S:
                raise RuntimeError(f"{what} did not answer in {READY_TIMEOUT_S} s")
            time.sleep(0.02)
        ready = time.monotonic() - t0
        kinds = by_kind(session_cpu(process.pid), process.pid)
    finally:
        process.terminate()
        try:
            process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, 9)
            process.wait()
    return {"ready_s": ready, "cpu_s": sum(kinds.values()), "kinds": dict(kinds)}


def summary(runs: list[dict]) -> dict:
    kinds = sorted({k for run in runs for k in run["kinds"]})
    return {
        "ready_s": {"median": statistics.median(r["ready_s"] for r in runs), "max": max(r["ready_s"] for r in runs)},
        "cpu_s": {"median": statistics.median(r["cpu_s"] for r in runs), "max": max(r["cpu_s"] for r in runs)},
        "cpu_s_median_by_kind": {k: statistics.median(r["kinds"].get(k, 0.0) for r in runs) for k in kinds},
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--before", default=BEFORE, help=f"the earlier commit (default {BEFORE})")
    parser.add_argument("--rounds", type=int, default=10, help="counted starts of each side (default 10)")
    parser.add_argument(
        "--workers", type=int, default=None, help="COATED_FIT_WORKERS (default: the service's, one per core)"
    )
    args = parser.parse_args(argv)
    if not 1 <= args.rounds <= 100:
        parser.error(f"--rounds must lie in [1, 100], got {args.rounds}")
    if args.workers is not None and not 1 <= args.workers <= 16:
        parser.error(f"--workers must lie in [1, 16], got {args.workers}")
    load = load_average()
    with checkout(args.before) as before:
        sides = {"before": before, "now": ROOT}
        for root in sides.values():
            start(root, args.workers)  # bytecode caches, not counted
        runs = {name: [] for name in sides}
        for i in range(args.rounds):
            for name in ("before", "now") if i % 2 == 0 else ("now", "before"):
                runs[name].append(start(sides[name], args.workers))
    figures = {name: summary(side) for name, side in runs.items()}
    figures["ratio_cpu_median"] = figures["now"]["cpu_s"]["median"] / figures["before"]["cpu_s"]["median"]
    figures["ratio_ready_median"] = figures["now"]["ready_s"]["median"] / figures["before"]["ready_s"]["median"]
    kinds = sorted({k for side in ("before", "now") for k in figures[side]["cpu_s_median_by_kind"]})
    print(
        f"python -m service, {args.rounds} starts a side (COATED_FIT_WORKERS={args.workers or 'default'}); "
        f"before = {args.before}"
    )
    print(f"{'':<36}{'before':>10}{'now':>10}")
    for label, key in (
        ("ready s, median", ("ready_s", "median")),
        ("ready s, max", ("ready_s", "max")),
        ("CPU s, median", ("cpu_s", "median")),
        ("CPU s, max", ("cpu_s", "max")),
    ):
        print(f"{label:<36}" + "".join(f"{figures[s][key[0]][key[1]]:>10.2f}" for s in ("before", "now")))
    for kind in kinds:
        print(
            f"{'  CPU s, ' + kind + ', median':<36}"
            + "".join(f"{figures[s]['cpu_s_median_by_kind'].get(kind, 0.0):>10.2f}" for s in ("before", "now"))
        )
    print(
        f"ratio of the medians (now / before): CPU {figures['ratio_cpu_median']:.2f}, "
        f"ready {figures['ratio_ready_median']:.2f}"
    )
    write_result("server_start", figures, load, before=args.before, rounds=args.rounds, workers=args.workers, runs=runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
