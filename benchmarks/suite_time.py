"""
Test suite wall time
====================

Runs the README's test command in its modes, one after another, and
records each one's wall time, test count and the load average around it in
``benchmarks/results/suite_time.json`` (quoted by docs/testing.md):

-   ``scripts/test --quick`` (target: under 1 minute on 2 cores);
-   ``scripts/test`` (the full suite on both cores; target: under 6 minutes);
-   ``scripts/test --other-cpus`` (the numeric tests under three other
    kernels' settings), unless ``--no-other-cpus``.

    .venv/bin/python benchmarks/suite_time.py [--rounds N] [--no-other-cpus] [--log DIR]
    .venv/bin/python benchmarks/suite_time.py --before REV [--rounds N] [--name NAME] [--log DIR]

``--rounds N`` runs the quick loop and the full suite N times each, in
turns (quick, full, quick, full, ...), then ``--other-cpus`` once: every
run is a row, and ``figures`` holds each mode's median and worst (the
largest wall time), so a record says how far the slowest of its runs is
from the target beside the typical one.

``--log DIR`` keeps each run's whole output (``DIR/quick.log``,
``full.log``, ``other-cpus.log``; ``quick-1.log``, ``full-1.log`` and so
on for the later rounds), for what a failed run printed.

``--before REV``: instead, the full suite of a checkout of ``REV`` (a git
worktree, what ``scripts/bootstrap`` installed linked in) and of this
checkout, in turns (``--rounds`` of each, the order swapped every round),
so that both run in the same hour of a machine whose speed drifts by a
quarter from one hour to the next; recorded in
``benchmarks/results/suite_time_side_by_side.json`` (or ``--name``'s
record). Each side runs
:data:`FULL_SUITE`, ``scripts/test``'s full mode after its set-up
(``scripts/bootstrap`` would set up the worktree's own environment):
bytecode caches written, then pytest with this checkout's interpreter.

A run with other work on the machine is slower; the load average says how
busy it was (1 minute average at the start and the end of each mode). Each
mode's CPU time, the machine's busy, idle and steal seconds over its run
(``/proc/stat``), says how far its wall time is from what 2 cores allow
(busy / 2); ``benchmarks/suite_cpu.py`` says which processes spent it.
Before each mode, ``calibration_s``: the seconds a fixed pure-Python loop
takes (:func:`calibration`), the interpreter's speed on one core then; and
``calibration_memory_s``: the seconds 8 copies of a 128 MiB array take
(:func:`memory_calibration`), the memory bandwidth one core gets then,
which neighbours on the host share and the loop (in the core's caches)
does not see.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import cpu  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results" / "suite_time.json"
SIDE_BY_SIDE = ROOT / "benchmarks" / "results" / "suite_time_side_by_side.json"
FULL_SUITE = ("-m", "pytest", "-n", "2", "--dist", "loadscope", "--durations=25", "-p", "no:cacheprovider")
"""``scripts/test``'s full mode: the interpreter's arguments after its set-up (tests/benchmarks checks they agree)."""
COMPILED = ("fitting", "service", "preview_shaders", "benchmarks")
"""The packages whose bytecode caches ``scripts/test`` writes before it runs the suite (checked likewise)."""
SUMMARY = re.compile(r"^=*\s*((?:\d+ \w+, )*\d+ (?:passed|failed).*?) in [\d.]+s", re.M)
FAILURE = re.compile(r"^(?:FAILED|ERROR) .*$", re.M)
TICK = os.sysconf("SC_CLK_TCK")


def calibration(rounds: int = 3) -> float:
    """
    Seconds of CPU time a fixed pure-Python loop takes here (the best of
    ``rounds``): the interpreter's speed on one core at the moment. The suite's own
    CPU seconds have varied by a third between runs where this loop did not
    (docs/testing.md), so it tells one cause of a slow run apart, not all.
    """
    best = float("inf")
    for _ in range(rounds):
        start, total = time.process_time(), 0
        for i in range(2_000_000):
            total += i * i % 7
        best = min(best, time.process_time() - start)
    return round(best, 3)


def memory_calibration(rounds: int = 3) -> float:
    """
    CPU seconds 8 copies of a 128 MiB float64 array into another take here
    (the best of ``rounds``): 2 GiB read and written, far past the caches, so the
    memory bandwidth one core gets at the moment.
    """
    import numpy as np

    source = np.ones(16 * 2**20)
    target = np.empty_like(source)
    best = float("inf")
    for _ in range(rounds):
        start = time.process_time()
        for _ in range(8):
            np.copyto(target, source)
        best = min(best, time.process_time() - start)
    return round(best, 3)


def machine_ticks() -> dict[str, int]:
    """/proc/stat's first line: busy (user, nice, system, irq, softirq), idle (with iowait) and steal ticks."""
    v = [int(x) for x in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    return {"busy": v[0] + v[1] + v[2] + v[5] + v[6], "idle": v[3] + v[4], "steal": v[7]}


def mode_name(args: list[str]) -> str:
    """``quick``, ``full`` or ``other-cpus``: the mode ``scripts/test ARGS`` runs."""
    return args[0].lstrip("-") if args else "full"


def run(args: list[str], log: Path | None = None, round_: int = 0) -> dict:
    """``scripts/test ARGS`` in this checkout, timed (``--quick``, the full suite, ``--other-cpus``)."""
    mode = mode_name(args)
    name = mode + (f"-{round_}" if round_ else "")
    return {"mode": mode, "round": round_, **timed(["scripts/test", *args], ROOT, log, f"{name}.log")}


def mode_figures(rows: list[dict]) -> dict:
    """
    Each mode's runs: ``runs``, ``median_s`` and ``worst_s`` (the largest
    wall time), and ``all_passed`` (every run's return code 0).
    """
    figures = {}
    for mode in dict.fromkeys(r["mode"] for r in rows):
        mine = [r for r in rows if r["mode"] == mode]
        seconds = [r["seconds"] for r in mine]
        figures[mode] = {
            "runs": len(mine),
            "median_s": round(statistics.median(seconds), 1),
            "worst_s": max(seconds),
            "all_passed": all(r["returncode"] == 0 for r in mine),
        }
    return figures


def full_suite(root: Path, log: Path | None = None, name: str = "full.log") -> dict:
    """:data:`FULL_SUITE` in the checkout ``root``, timed, after its bytecode caches (as ``scripts/test`` writes them)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    subprocess.run(
        [sys.executable, "-m", "compileall", "-q", *COMPILED], cwd=root, env=env, capture_output=True, check=True
    )
    return timed([sys.executable, *FULL_SUITE], root, log, name, env)


def timed(command: list[str], cwd: Path, log: Path | None, name: str, env: dict | None = None) -> dict:
    speed, memory = calibration(), memory_calibration()
    load_start, ticks = os.getloadavg()[0], machine_ticks()
    start = time.perf_counter()
    done = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    ticks = {k: round((v - ticks[k]) / TICK, 1) for k, v in machine_ticks().items()}
    output = done.stdout + done.stderr
    if log is not None:
        log.mkdir(parents=True, exist_ok=True)
        (log / name).write_text(output)
    summaries = SUMMARY.findall(output)
    shown = command if command[0] == "scripts/test" else ["python", *command[1:]]
    return {
        "command": " ".join(shown),
        "seconds": round(seconds, 1),
        "returncode": done.returncode,
        "summaries": summaries,
        "failures": FAILURE.findall(output)[:50],  # what failed, when a run did
        "load_average": [round(load_start, 2), round(os.getloadavg()[0], 2)],
        "machine_seconds": ticks,
        "calibration_s": speed,
        "calibration_memory_s": memory,
    }


def side_by_side(before: str, rounds: int, log: Path | None) -> dict:
    """The full suite of ``before`` and of this checkout in turns, ``rounds`` of each; medians and their ratios."""
    from benchmarks.side_by_side import SUITE_INSTALLED, checkout

    rows = []
    with checkout(before, SUITE_INSTALLED) as root:
        for i in range(rounds):
            for side in ("before", "now") if i % 2 == 0 else ("now", "before"):
                row = full_suite(root if side == "before" else ROOT, log, f"full-{side}-{i}.log")
                rows.append({"checkout": side, **row})
                print(
                    f"round {i}, {side}: {row['seconds']:.1f} s, busy {row['machine_seconds']['busy']:.1f} s, "
                    f"calibration {row['calibration_s']:.3f} s, memory {row['calibration_memory_s']:.3f} s, "
                    f"{'; '.join(row['summaries'])}",
                    flush=True,
                )
    figures = {}
    for side in ("before", "now"):
        mine = [r for r in rows if r["checkout"] == side]
        figures[side] = {
            "seconds": statistics.median(r["seconds"] for r in mine),
            "busy_seconds": statistics.median(r["machine_seconds"]["busy"] for r in mine),
            "idle_seconds": statistics.median(r["machine_seconds"]["idle"] for r in mine),
            "summaries": [r["summaries"][-1:] for r in mine],
        }
    figures["ratio_seconds"] = figures["now"]["seconds"] / figures["before"]["seconds"]
    figures["ratio_busy"] = figures["now"]["busy_seconds"] / figures["before"]["busy_seconds"]
    return {"before": before, "rounds": rounds, "figures": figures, "rows": rows}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--no-other-cpus", action="store_true", help="leave out --other-cpus")
    parser.add_argument("--log", type=Path, help="keep each mode's whole output in this directory")
    parser.add_argument(
        "--before", metavar="REV", help="instead: the full suite of this commit and of this checkout, in turns"
    )
    parser.add_argument(
        "--rounds",
        type=int,
        default=1,
        help="runs of the quick loop and of the full suite each (with --before: full runs of each side); default 1",
    )
    parser.add_argument(
        "--name",
        default=SIDE_BY_SIDE.stem,
        help=f"with --before: the record, benchmarks/results/NAME.json (default {SIDE_BY_SIDE.stem})",
    )
    args = parser.parse_args(argv)
    if not 1 <= args.rounds <= 5:
        parser.error(f"--rounds must lie in [1, 5], got {args.rounds}")
    if not re.fullmatch(r"suite_time_[a-z0-9_]+", args.name):
        parser.error(f"--name must be suite_time_ and lower-case letters, digits or _, got {args.name!r}")
    if args.before is not None:
        if (
            subprocess.run(
                ["git", "-C", str(ROOT), "rev-parse", "--verify", "--quiet", f"{args.before}^{{commit}}"],
                capture_output=True,
            ).returncode
            != 0
        ):
            parser.error(f"--before must name a commit of this repository, got {args.before!r}")
        result = side_by_side(args.before, args.rounds, args.log)
        f = result["figures"]
        print(f"{'':<8}{'wall s':>9}{'busy s':>9}{'idle s':>9}")
        for side in ("before", "now"):
            print(f"{side:<8}{f[side]['seconds']:>9.1f}{f[side]['busy_seconds']:>9.1f}{f[side]['idle_seconds']:>9.1f}")
        print(f"now / before: wall {f['ratio_seconds']:.3f}, busy {f['ratio_busy']:.3f}")
        (SIDE_BY_SIDE.parent / f"{args.name}.json").write_text(
            json.dumps(
                {
                    "command": "benchmarks/suite_time.py " + " ".join(argv if argv is not None else sys.argv[1:]),
                    "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
                    "cpu": cpu(),
                    **result,
                },
                indent=2,
            )
            + "\n"
        )
        return max(r["returncode"] for r in result["rows"])
    rows = [run(mode, args.log, i) for i in range(args.rounds) for mode in (["--quick"], [])]
    rows += [] if args.no_other_cpus else [run(["--other-cpus"], args.log)]
    figures = mode_figures(rows)
    print(
        f"{'command':<28} {'round':>5} {'wall s':>8} {'min':>6} {'rc':>3} {'load':>11} {'busy s':>7} {'idle s':>7} "
        f"{'calib s':>7} {'mem s':>6}  tests"
    )
    for r in rows:
        print(
            f"{r['command']:<28} {r['round']:>5} {r['seconds']:>8.1f} {r['seconds'] / 60:>6.2f} {r['returncode']:>3} "
            f"{r['load_average'][0]:>5.2f}-{r['load_average'][1]:<5.2f} {r['machine_seconds']['busy']:>7.1f} "
            f"{r['machine_seconds']['idle']:>7.1f} {r['calibration_s']:>7.3f} {r['calibration_memory_s']:>6.3f}  "
            f"{'; '.join(r['summaries'])}"
        )
    print(f"\n{'mode':<12} {'runs':>4} {'median s':>9} {'worst s':>8}  all passed")
    for mode, f in figures.items():
        print(f"{mode:<12} {f['runs']:>4} {f['median_s']:>9.1f} {f['worst_s']:>8.1f}  {f['all_passed']}")
    for r in rows:
        for failure in r["failures"]:
            print(f"{r['command']}: {failure}")
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(
        json.dumps(
            {
                "command": "benchmarks/suite_time.py " + " ".join(argv if argv is not None else sys.argv[1:]),
                "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
                "cpu": cpu(),
                "rounds": args.rounds,
                "figures": figures,
                "rows": rows,
            },
            indent=2,
        )
        + "\n"
    )
    return max(r["returncode"] for r in rows)


if __name__ == "__main__":
    sys.exit(main())
