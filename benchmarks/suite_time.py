"""
Test suite wall time
====================

Runs the README's test command in its modes, one after another, and
records each one's wall time, test count and the load average around it in
``benchmarks/results/suite_time.json`` (quoted by docs/testing.md):

-   ``scripts/test --quick`` (target: under 2 minutes on 2 cores);
-   ``scripts/test`` (the full suite on both cores; target: under 6 minutes);
-   ``scripts/test --other-cpus`` (the numeric tests under three other
    kernels' settings), unless ``--no-other-cpus``.

    .venv/bin/python benchmarks/suite_time.py [--no-other-cpus] [--log DIR]

``--log DIR`` keeps each mode's whole output (``DIR/quick.log``,
``full.log``, ``other-cpus.log``), for what a failed run printed.

A run with other work on the machine is slower; the load average says how
busy it was (1 minute average at the start and the end of each mode). Each
mode's CPU time, the machine's busy, idle and steal seconds over its run
(``/proc/stat``), says how far its wall time is from what 2 cores allow
(busy / 2); ``benchmarks/suite_cpu.py`` says which processes spent it.
Before each mode, ``calibration_s``: the seconds a fixed pure-Python loop
takes (:func:`calibration`), the interpreter's speed on one core then.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import cpu  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results" / "suite_time.json"
SUMMARY = re.compile(r"^=*\s*((?:\d+ \w+, )*\d+ (?:passed|failed).*?) in [\d.]+s", re.M)
FAILURE = re.compile(r"^(?:FAILED|ERROR) .*$", re.M)
TICK = os.sysconf("SC_CLK_TCK")


def calibration() -> float:
    """
    Seconds of CPU time a fixed pure-Python loop takes here (the best of
    3): the interpreter's speed on one core at the moment. The suite's own
    CPU seconds have varied by a third between runs where this loop did not
    (docs/testing.md), so it tells one cause of a slow run apart, not all.
    """
    best = float("inf")
    for _ in range(3):
        start, total = time.process_time(), 0
        for i in range(2_000_000):
            total += i * i % 7
        best = min(best, time.process_time() - start)
    return round(best, 3)


def machine_ticks() -> dict[str, int]:
    """/proc/stat's first line: busy (user, nice, system, irq, softirq), idle (with iowait) and steal ticks."""
    v = [int(x) for x in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    return {"busy": v[0] + v[1] + v[2] + v[5] + v[6], "idle": v[3] + v[4], "steal": v[7]}


def run(args: list[str], log: Path | None = None) -> dict:
    speed = calibration()
    load_start, ticks = os.getloadavg()[0], machine_ticks()
    start = time.perf_counter()
    done = subprocess.run(["scripts/test", *args], cwd=ROOT, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    ticks = {k: round((v - ticks[k]) / TICK, 1) for k, v in machine_ticks().items()}
    output = done.stdout + done.stderr
    if log is not None:
        log.mkdir(parents=True, exist_ok=True)
        (log / f"{args[0].lstrip('-') if args else 'full'}.log").write_text(output)
    summaries = SUMMARY.findall(output)
    return {"command": " ".join(["scripts/test", *args]), "seconds": round(seconds, 1),
            "returncode": done.returncode, "summaries": summaries,
            "failures": FAILURE.findall(output)[:50],  # what failed, when a run did
            "load_average": [round(load_start, 2), round(os.getloadavg()[0], 2)],
            "machine_seconds": ticks, "calibration_s": speed}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--no-other-cpus", action="store_true", help="leave out --other-cpus")
    parser.add_argument("--log", type=Path, help="keep each mode's whole output in this directory")
    args = parser.parse_args(argv)
    modes = [["--quick"], []] + ([] if args.no_other_cpus else [["--other-cpus"]])
    rows = [run(mode, args.log) for mode in modes]
    print(f"{'command':<28} {'wall s':>8} {'min':>6} {'rc':>3} {'load':>11} {'busy s':>7} {'idle s':>7} "
          f"{'calib s':>7}  tests")
    for r in rows:
        print(f"{r['command']:<28} {r['seconds']:>8.1f} {r['seconds'] / 60:>6.2f} {r['returncode']:>3} "
              f"{r['load_average'][0]:>5.2f}-{r['load_average'][1]:<5.2f} {r['machine_seconds']['busy']:>7.1f} "
              f"{r['machine_seconds']['idle']:>7.1f} {r['calibration_s']:>7.3f}  {'; '.join(r['summaries'])}")
    for r in rows:
        for failure in r["failures"]:
            print(f"{r['command']}: {failure}")
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps({
        "command": "benchmarks/suite_time.py " + " ".join(argv if argv is not None else sys.argv[1:]),
        "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
        "cpu": cpu(), "rows": rows,
    }, indent=2) + "\n")
    return max(r["returncode"] for r in rows)


if __name__ == "__main__":
    sys.exit(main())
