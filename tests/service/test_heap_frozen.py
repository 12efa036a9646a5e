"""
The garbage collector's full passes kept off the request path:
the server and every fitting worker freeze what start-up made
(service.runtime.worker.freeze_heap), so a full collection traverses only what
requests made since; the service thaws it at shutdown. Before, a full
collection of 60-86 ms in the server landed on a live refit step
(benchmarks/live_overhead.py --gc-trace).
"""

from __future__ import annotations

import asyncio
import gc

import pytest
from conftest import app_client

from service.runtime.pool import FitRunner

pytestmark = pytest.mark.slow  # worker processes, an in-process service

# Far fewer than what importing the core, colour-science and FastAPI makes
# (hundreds of thousands of objects): a frozen start-up heap is above it.
START_UP_OBJECTS = 10_000


def test_each_fitting_worker_freezes_its_start_up_heap():
    async def body():
        runner = FitRunner(1, 4, timeout_s=60.0)
        try:
            await runner.warm_up()
            return await runner.run(gc.get_freeze_count)
        finally:
            runner.close()

    assert asyncio.run(body()) > START_UP_OBJECTS


def test_the_service_freezes_its_heap_while_it_runs_and_thaws_it_at_shutdown(tmp_path):
    gc.unfreeze()  # whatever an earlier test left
    with app_client(tmp_path, freeze_heap=True) as client:
        assert client.get("/healthz").status_code == 200
        assert gc.get_freeze_count() > START_UP_OBJECTS
    assert gc.get_freeze_count() == 0


def test_an_embedded_app_leaves_its_host_s_heap_alone(tmp_path):
    """COATED_FREEZE_HEAP off (the tests' in-process clients): no collection of the host's heap, no freeze."""
    gc.unfreeze()
    with app_client(tmp_path, freeze_heap=False) as client:
        assert client.get("/healthz").status_code == 200
        assert gc.get_freeze_count() == 0
    assert gc.get_freeze_count() == 0
