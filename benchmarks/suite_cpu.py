"""
Where the full suite's CPU time goes
====================================

Runs the README's full test command (``scripts/test``) once while it
samples ``/proc`` every ``--interval`` seconds (0.25): each process's own
CPU time (user and system, all its threads, ``/proc/PID/stat``), kept per
process under a class read from its command line (the pytest processes,
the service's server processes, their fork servers and workers, Chromium's
browser, renderer and GPU processes, playwright's Node.js driver, the CLI
runs, PostgreSQL, kernel threads, this sampler; :data:`CLASSES`), and the
machine's busy, idle and steal time from ``/proc/stat``. Records the table
in ``benchmarks/results/suite_cpu.json`` (``classes.<key>.cpu_seconds``,
quoted by docs/testing.md):

    .venv/bin/python benchmarks/suite_cpu.py [--interval S] [--log DIR]

``--log DIR`` keeps the suite's whole output (``DIR/full.log``). The record also holds
:func:`benchmarks.suite_time.calibration`, the seconds a fixed pure-Python
loop took just before the run (the interpreter's speed on one core then;
the suite's CPU seconds vary from one hour to the next by more than it
does). "this sampler" is this process: the sampler and that loop.

The full suite's wall time on 2 cores is bounded below by its busy CPU
time over 2, so this says what a shorter run has to take CPU time from. A
process that starts and ends between two samples is not seen; what the
classes miss of the machine's busy time is the row "not seen". The
sampler's own CPU time is its row; it makes this run a little slower than
``benchmarks/suite_time.py``'s, whose wall times are the record of speed.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import threading
from collections import Counter
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import cpu  # noqa: E402
from benchmarks.suite_time import TICK, run  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results" / "suite_cpu.json"

CLASSES = (
    # (key in the record, what it is, substrings of the command line naming it); the first match wins
    ("chromium_renderer", "Chromium renderer", ("--type=renderer",)),
    ("chromium_gpu", "Chromium GPU process (SwiftShader)", ("--type=gpu-process",)),
    ("chromium_other", "Chromium other (zygote, utility)", ("--type=",)),
    ("chromium_browser", "Chromium browser", ("chromium", "chrome")),
    # and a server's forks (its fork server, service.runtime.fork_server.start_fork_server, and their workers): classify()
    ("fork_servers", "fork servers and their workers", ("multiprocessing.forkserver",)),
    ("servers", "server processes (python -m service)", ("-m service", "tests/server_forks.py")),
    # the second: pytest-xdist's workers
    ("pytest", "pytest processes", ("pytest", "exec(eval(sys.stdin.readline()))")),
    ("playwright", "playwright's Node.js driver", ("playwright",)),
    ("node", "other Node.js (glTF validator, three.js)", ("node",)),
    ("postgres", "PostgreSQL", ("postgres",)),
    ("blender", "Blender", ("blender", "bpy")),
    ("cli", "CLI runs (python -m fitting, benchmarks)", ("-m fitting", "-m benchmarks")),
)
OTHERS = {
    "other_python": "other Python processes",
    "other": "other programs",
    "kernel": "kernel threads",
    "sampler": "this sampler",
    "not_seen": "not seen (processes that lived between two samples)",
}
LABELS = {key: label for key, label, _ in CLASSES} | OTHERS


def classify(command: str, parent: str | None = None, leader: bool = False) -> str:
    """
    The key of a process's class by its command line (:data:`CLASSES`), its
    parent's class and whether it leads its session: a server's fork (its
    fork server and the workers, which keep the server's command line) is
    ``fork_servers``; a server forked by tests/server_forks.py (which has
    that program's command line) leads a session of its own, as a
    ``python -m service`` the tests start does, and is ``servers``.
    """
    if not command:  # kernel threads have none
        return "kernel"
    for key, _, needles in CLASSES:
        if any(n in command for n in needles):
            forked = key == "servers" and parent in ("servers", "fork_servers") and not leader
            return "fork_servers" if forked else key
    return "other_python" if "python" in command else "other"


class Sampler(threading.Thread):
    """Every ``interval`` seconds: each live process's CPU ticks so far, kept by (pid, start time)."""

    def __init__(self, interval: float) -> None:
        super().__init__(daemon=True)
        self.interval, self.done = interval, threading.Event()
        # (pid, start) -> [class, ticks counted from, last ticks, samples that read the command line]
        self.seen: dict[tuple[str, str], list] = {}
        self.me = str(os.getpid())
        self.classes: dict[str, str] = {}  # pid -> the class of the process last seen with it (a child's parent)
        self.started = False  # after the first sample: a process first seen since then counts from 0

    def sample(self) -> None:
        for pid in os.listdir("/proc"):
            if not pid.isdigit():
                continue
            try:
                stat = Path(f"/proc/{pid}/stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rfind(")") + 2 :].split()
            ticks, key = int(fields[11]) + int(fields[12]), (pid, fields[19])
            parent = self.classes.get(fields[1])
            entry = self.seen.get(key)
            if entry is None:
                self.seen[key] = entry = [None, ticks if not self.started else 0, ticks, 0]
            if entry[3] < 2:  # read twice: a child seen between its fork and its exec has its parent's
                try:
                    command = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
                except OSError:
                    command = ""
                if command or entry[0] is None:  # a process gone since (or a zombie) keeps its class
                    entry[0] = "sampler" if pid == self.me else classify(command, parent, fields[3] == pid)
                entry[3] += 1
            entry[2] = max(entry[2], ticks)
            self.classes[pid] = entry[0]

    def run(self) -> None:
        self.sample()  # what the processes running now spent before is not the suite's
        self.started = True
        while not self.done.wait(self.interval):
            self.sample()
        self.sample()

    def totals(self) -> Counter:
        out = Counter()
        for label, first, last, _ in self.seen.values():
            out[label] += (last - first) / TICK
        return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--interval", type=float, default=0.25, help="seconds between samples (default 0.25)")
    parser.add_argument("--log", type=Path, help="keep the suite's whole output in this directory (full.log)")
    args = parser.parse_args(argv)
    if not 0.01 <= args.interval <= 5:
        parser.error(f"--interval must lie in [0.01, 5] seconds, got {args.interval}")
    sampler = Sampler(args.interval)
    sampler.start()
    result = run([], args.log)  # the full suite, as benchmarks/suite_time.py runs it
    sampler.done.set()
    sampler.join()
    machine, seconds, speed = result["machine_seconds"], result["seconds"], result["calibration_s"]
    classes = sampler.totals()
    classes["not_seen"] = machine["busy"] - sum(classes.values())
    rows = {
        k: {"class": LABELS[k], "cpu_seconds": round(classes[k], 1), "share": round(classes[k] / machine["busy"], 3)}
        for k in sorted(LABELS, key=lambda k: -classes[k])
    }
    print(
        f"scripts/test: {seconds:.0f} s wall, returncode {result['returncode']}; machine: busy {machine['busy']} s, "
        f"idle {machine['idle']} s, steal {machine['steal']} s of CPU time ({os.cpu_count()} cores); "
        f"calibration loop {speed} s"
    )
    print(f"{'class':<54} {'CPU s':>8} {'share':>6}")
    for row in rows.values():
        print(f"{row['class']:<54} {row['cpu_seconds']:>8.1f} {row['share']:>6.1%}")
    for failure in result["failures"]:
        print(failure)
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(
        json.dumps(
            {
                "command": "benchmarks/suite_cpu.py " + " ".join(argv if argv is not None else sys.argv[1:]),
                "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
                "cpu": cpu(),
                "wall_seconds": seconds,
                "returncode": result["returncode"],
                "summary": result["summaries"][-1:],
                "failures": result["failures"],
                "load_average": result["load_average"],
                "calibration_s": speed,
                "machine_seconds": machine,
                "classes": rows,
            },
            indent=2,
        )
        + "\n"
    )
    return result["returncode"]


if __name__ == "__main__":
    sys.exit(main())
