"""
service.runtime.pool: every part of a job has a CPU-time limit, and a job
no request waits for any more (timed out, or its client gone) is cancelled,
its worker free within a second. Real worker processes (forked by the fork server).
"""

from __future__ import annotations

import asyncio
import time

import numpy as np
import pytest

from service.runtime.budget import BUDGET_FACTOR, JobBudgetExceeded
from service.runtime.pool import FitRunner, FitTimeout, JobCPULimit, Quarantined, WorkerLost

pytestmark = pytest.mark.slow


def degenerate_refit() -> float:
    """A worst-case curve refit (a base with no conductor), ~0.5 s of CPU."""
    from fitting.fits.curves import fit_curves
    from fitting.fits.curves_base import curve_base_from_nk
    from fitting.optics.nk import SpectralNK

    base = curve_base_from_nk(SpectralNK(np.array([300.0, 900.0]), np.ones(2), np.zeros(2), name="void"))
    angles = np.linspace(0.0, 90.0, 16)
    curves = [{"eta_i": 1.5, "angle_deg": angles.tolist(), "rgb": np.full((16, 3), 0.5).tolist()}]
    return fit_curves(curves, base).metrics["delta_E_mean"]


def worker_modules() -> dict:
    """In a worker: what it started with (from the fork server's service.runtime.preload)."""
    import sys

    from fitting.colour import reference

    return {
        "colour": "colour" in sys.modules,
        "scipy.optimize": "scipy.optimize" in sys.modules,
        "matplotlib": "matplotlib" in sys.modules,
        "weights_cached": reference._weights.cache_info().currsize,
    }


async def _with_runner(body, **kwargs):
    runner = FitRunner(1, 4, **kwargs)
    try:
        await runner.warm_up()
        return await body(runner)
    finally:
        runner.close()


def test_workers_start_with_the_core_warm_and_without_matplotlib():
    """The fork server imports colour-science as the core does (its plotting, and matplotlib, only on use)."""

    async def body(runner):
        return await runner.run(worker_modules)

    seen = asyncio.run(_with_runner(body, timeout_s=60.0))
    assert seen["colour"] and seen["scipy.optimize"] and seen["weights_cached"] >= 2, seen
    assert not seen["matplotlib"], seen


def test_a_part_past_its_cpu_limit_is_stopped_with_a_clear_error():
    async def body(runner):
        with pytest.raises(JobCPULimit, match=r"CPU-time limit of 0\.05 s"):
            await runner.run(degenerate_refit)
        return await runner.run(time.time)  # the worker serves the next job

    assert asyncio.run(_with_runner(body, timeout_s=60.0, cpu_limit_s=0.05)) > 0


def burn(cpu_s: float) -> float:
    """A part that uses ``cpu_s`` seconds of CPU."""
    start = time.process_time()
    while time.process_time() - start < cpu_s:
        pass
    return cpu_s


def test_a_job_of_parts_has_a_cpu_budget_proportional_to_its_estimate():
    """Parts within the part limit each, but past their job's budget together: the job is stopped, naming it."""

    async def body(runner):
        async with runner.slot(0.1):  # budget: max(0.5, 3 x 0.1) = 0.5 s; three parts of 0.2 s
            first = [await runner.submit(burn, 0.2, cost_s=0.03) for _ in range(2)]
            with pytest.raises(JobBudgetExceeded, match=r"CPU budget of 0\.5 s \(3 x its estimated 0\.1 s"):
                await runner.submit(burn, 0.2, cost_s=0.03)
            with pytest.raises(JobBudgetExceeded):  # spent: the next part does not start
                await runner.submit(burn, 0.01, cost_s=0.03)
        async with runner.slot(1.0):  # a larger estimate, a larger budget: 3 s
            larger = [await runner.submit(burn, 0.2, cost_s=0.03) for _ in range(3)]
        return first, larger, await runner.run(burn, 0.2)  # one part alone: the part limit

    assert BUDGET_FACTOR == 3.0
    first, larger, alone = asyncio.run(_with_runner(body, timeout_s=60.0, cpu_limit_s=0.5))
    assert first == [0.2, 0.2] and larger == [0.2] * 3 and alone == 0.2


def checked_input_for_two_seconds() -> str:
    """A job that spends its time in the core's input checks (``except ValueError`` around ``np.asarray``)."""
    from fitting.domain import as_float_array

    values, start = [1.5] * 200_000, time.process_time()
    while time.process_time() - start < 2.0:
        as_float_array("eta_t", values)
    return "not stopped"


def test_the_cpu_limit_is_not_taken_for_bad_input_by_the_job_s_own_checks():
    """The limit lands wherever the job is: inside an input check it is still the limit, not "must be numbers"."""

    async def body(runner):
        for _ in range(3):
            with pytest.raises(JobCPULimit, match=r"CPU-time limit of 0\.05 s"):
                await runner.run(checked_input_for_two_seconds)
        return await runner.run(time.time)

    assert asyncio.run(_with_runner(body, timeout_s=60.0, cpu_limit_s=0.05)) > 0


def test_a_timed_out_job_is_cancelled_and_its_worker_free_within_a_second():
    async def body(runner):
        with pytest.raises(FitTimeout):
            await runner.once("sleeper", lambda: runner.run(time.sleep, 30.0))
        t0 = time.perf_counter()
        await runner.run(time.time)
        return time.perf_counter() - t0

    assert asyncio.run(_with_runner(body, timeout_s=0.3)) < 1.0


def test_a_job_whose_waiter_is_cancelled_is_cancelled():
    # A client that disconnects cancels its request's task.
    async def body(runner):
        waiter = asyncio.ensure_future(runner.once("sleeper", lambda: runner.run(time.sleep, 30.0)))
        await asyncio.sleep(0.3)
        waiter.cancel()
        t0 = time.perf_counter()
        await runner.run(time.time)
        return time.perf_counter() - t0, runner.in_flight

    seconds, in_flight = asyncio.run(_with_runner(body, timeout_s=60.0))
    assert seconds < 1.0 and in_flight == 0


def test_a_shared_job_runs_on_while_one_waiter_remains():
    async def body(runner):
        make = lambda: runner.run(time.sleep, 0.6)  # noqa: E731
        first = asyncio.ensure_future(runner.once("shared", make))
        second = asyncio.ensure_future(runner.once("shared", make))
        await asyncio.sleep(0.2)
        first.cancel()
        return await second

    asyncio.run(_with_runner(body, timeout_s=60.0))


def test_a_job_that_kills_its_workers_fails_only_itself_and_is_quarantined():
    import os

    async def body(runner):
        others = [
            asyncio.ensure_future(runner.once(f"other{i}", lambda i=i: runner.run(time.sleep, 0.4))) for i in range(5)
        ]
        await asyncio.sleep(0.1)
        with pytest.raises(WorkerLost, match="three times"):
            await runner.once("killer", lambda: runner.run(os._exit, 1))
        results = await asyncio.gather(*others, return_exceptions=True)
        with pytest.raises(Quarantined):
            await runner.once("killer", lambda: runner.run(time.time))
        return results, await runner.run(time.time)

    async def with_two_workers():
        runner = FitRunner(2, 16, timeout_s=60.0, quarantine_s=30.0)
        try:
            await runner.warm_up()
            return await body(runner)
        finally:
            runner.close()

    results, after = asyncio.run(with_two_workers())
    assert results == [None] * 5, results  # every unrelated job answered
    assert after > 0


def test_turns_let_the_cheapest_waiting_part_go_first():
    from service.runtime.turns import Turns

    async def body():
        turns, order = Turns(1), []

        async def part(name, cost):
            async with turns.turn(cost):
                order.append(name)
                await asyncio.sleep(0.01)

        first = asyncio.ensure_future(part("first", 5.0))
        await asyncio.sleep(0)
        waiting = [
            asyncio.ensure_future(part(n, c))
            for n, c in (("slow", 5.0), ("cancelled", 0.01), ("cheap", 0.1), ("slow2", 5.0))
        ]
        await asyncio.sleep(0)
        waiting[1].cancel()
        await asyncio.gather(first, *waiting, return_exceptions=True)
        return order, turns.running

    order, running = asyncio.run(body())
    assert order == ["first", "cheap", "slow", "slow2"] and running == 0


def test_express_turns_take_cheap_parts_only_and_keep_expensive_work_at_n():
    """
    With every general turn on an expensive part, a cheap part starts at
    once on an express turn; an expensive part waits (it never takes an
    express turn); a freed express turn goes to the next cheap part only.
    """
    from service.runtime.turns import Turns

    async def body():
        turns, started = Turns(1, express=1, express_cost_s=0.1), []
        gates = {name: asyncio.Event() for name in ("slow", "cheap", "slow2", "cheap2")}

        async def part(name, cost):
            async with turns.turn(cost):
                started.append((name, turns.running, turns.express_running))
                await gates[name].wait()

        slow = asyncio.ensure_future(part("slow", 1.0))
        await asyncio.sleep(0)
        slow2 = asyncio.ensure_future(part("slow2", 1.0))
        cheap = asyncio.ensure_future(part("cheap", 0.1))
        await asyncio.sleep(0)
        assert [s[0] for s in started] == ["slow", "cheap"]  # slow2 waits: no express turn for it
        cheap2 = asyncio.ensure_future(part("cheap2", 0.05))
        await asyncio.sleep(0)
        gates["cheap"].set()
        await cheap
        await asyncio.sleep(0)
        assert [s[0] for s in started] == ["slow", "cheap", "cheap2"]  # the express turn to the cheap part
        gates["cheap2"].set()
        await cheap2
        await asyncio.sleep(0)
        assert turns.express_running == 0 and turns.running == 1  # slow2 still waits for the general turn
        gates["slow"].set()
        await slow
        await asyncio.sleep(0)
        gates["slow2"].set()
        await slow2
        return started, turns.running, turns.express_running

    started, running, express = asyncio.run(body())
    assert [s[0] for s in started] == ["slow", "cheap", "cheap2", "slow2"]
    assert max(s[1] for s in started) == 1 and max(s[2] for s in started) == 1
    assert running == 0 and express == 0


def test_turns_refuse_bad_counts():
    from service.runtime.turns import Turns

    with pytest.raises(ValueError, match="`n` must be >= 1"):
        Turns(0)
    with pytest.raises(ValueError, match="`express` >= 0"):
        Turns(1, express=-1)
