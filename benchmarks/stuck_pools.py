"""
Pools whose worker is killed while it sends a result
====================================================

What :mod:`service.runtime.executors` is for, measured. Each trial is a new pool
of two workers (Python's ``ProcessPoolExecutor``, forks of the service's
fork server: :func:`service.runtime.worker.process_context`) given one job
whose result is ``--mb`` MB; one worker is SIGKILLed from outside (as the
OOM killer would: the one with the most resident memory, the job's) at a random time in the first
``--window`` seconds after the submit: before, while or after its result is
sent. The same kill times (``--seed``) run twice, in turns:

-   ``plain``: the job awaited as ``asyncio.wrap_future`` (the service
    before :mod:`service.runtime.executors`);
-   ``watched``: awaited with :func:`service.runtime.executors.result`.

Each trial ends ``answered`` (the result came), ``broken`` (the pool saw
the death: ``BrokenProcessPool``) or ``hung`` (neither within ``--limit``
seconds; the pool is then unstuck with :func:`service.runtime.executors.unstick`
so that the next trial starts clean). Prints a table and records
benchmarks/results/stuck_pools.json (``figures``: per side the counts and
the median and max seconds from the kill to the outcome, hung trials
excluded).

Usage: python benchmarks/stuck_pools.py [--trials N] [--mb N] [--window S] [--limit S] [--seed N]
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import os
import random
import signal
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from service.runtime import executors  # noqa: E402
from service.runtime.worker import process_context  # noqa: E402

SIDES = ("plain", "watched")


def sized_result(size: int) -> bytes:
    """The job: ``size`` bytes, made, pickled and sent by the worker."""
    return b"x" * size


def _resident(pid: int) -> int:
    """Resident pages of process ``pid`` (0 once it is gone)."""
    try:
        return int(Path(f"/proc/{pid}/statm").read_text().split()[1])
    except (OSError, IndexError, ValueError):
        return 0


async def trial(side: str, size: int, kill_after_s: float | None, limit_s: float) -> tuple[str, float | None]:
    """
    One pool, one job, one worker killed ``kill_after_s`` after the submit
    (``None``: none); the outcome and the seconds from the kill to it.
    """
    pool = concurrent.futures.ProcessPoolExecutor(2, mp_context=process_context())  # the service's fork server
    try:
        for _ in range(4):  # both workers started
            pool.submit(os.getpid).result()
        future = pool.submit(sized_result, size)
        waited = asyncio.wrap_future(future) if side == "plain" else executors.result(pool, future)
        task = asyncio.ensure_future(waited)
        killed = time.monotonic()
        if kill_after_s is not None:
            await asyncio.sleep(kill_after_s)
            killed = time.monotonic()
            os.kill(max(pool._processes, key=_resident), signal.SIGKILL)  # as the OOM killer picks
        try:
            await asyncio.wait_for(task, limit_s)
            outcome = "answered"
        except concurrent.futures.process.BrokenProcessPool:
            outcome = "broken"
        except asyncio.TimeoutError:
            return "hung", None
        return outcome, time.monotonic() - killed
    finally:
        if executors.has_dead_worker(pool):
            executors.unstick(pool)
        pool.shutdown(wait=True, cancel_futures=True)


def _bounded(name: str, low: float, high: float, kind: type = float):
    def parse(text: str):
        value = kind(text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"--{name} must lie in [{low:g}, {high:g}], got {text}")
        return value

    return parse


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=_bounded("trials", 1, 200, int), default=12)
    parser.add_argument("--mb", type=_bounded("mb", 1, 1000, int), default=300)
    parser.add_argument("--window", type=_bounded("window", 0.01, 10), default=0.6)
    parser.add_argument("--limit", type=_bounded("limit", 1, 120), default=15.0)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    load_at_start = load_average()
    kills = [random.Random(args.seed + i).uniform(0.05, args.window) for i in range(args.trials)]
    size = args.mb << 20
    runs: dict[str, list[tuple[str, float | None]]] = {side: [] for side in SIDES}
    for i, kill in enumerate(kills):
        for side in SIDES if i % 2 == 0 else SIDES[::-1]:
            runs[side].append(asyncio.run(trial(side, size, kill, args.limit)))
            print(f"trial {i} {side}: kill after {kill:.2f} s -> {runs[side][-1][0]}", flush=True)
    figures = {}
    print("\n| side | trials | answered | broken | hung | kill to outcome, median / max s |")
    print("|---|---:|---:|---:|---:|---:|")
    for side in SIDES:
        outcomes = [outcome for outcome, _ in runs[side]]
        seconds = [s for _, s in runs[side] if s is not None]
        figures[side] = {
            "trials": len(outcomes),
            **{k: outcomes.count(k) for k in ("answered", "broken", "hung")},
            "seconds_median": round(statistics.median(seconds), 2) if seconds else None,
            "seconds_max": round(max(seconds), 2) if seconds else None,
        }
        f = figures[side]
        print(
            f"| {side} | {f['trials']} | {f['answered']} | {f['broken']} | {f['hung']} | "
            f"{f['seconds_median']} / {f['seconds_max']} |"
        )
    path = write_result(
        "stuck_pools",
        figures,
        load_at_start,
        kills_s=[round(k, 3) for k in kills],
        settings={"mb": args.mb, "limit_s": args.limit, "stuck_s": executors.STUCK_S, "watch_s": executors.WATCH_S},
        runs={side: [[o, None if s is None else round(s, 3)] for o, s in runs[side]] for side in SIDES},
    )
    print(f"\nrecorded {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
