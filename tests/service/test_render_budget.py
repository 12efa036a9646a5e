"""
Each render's CPU budget, against a real ``python -m service`` on
127.0.0.1 (``COATED_JOB_CPU_LIMIT_S=5``):

-   a preview whose estimated CPU seconds pass the CPU-time limit of a job
    (2048 px, rough and coated, with the spectral reference) is refused
    before it renders (422 naming the limit) and the service still renders;
-   a client's previews in flight are admitted by their estimates: a 1448 px
    rough preview (2.9 s) of a client already rendering a 2048 px smooth one
    (2.3 s) passes its share (503 with ``Retry-After``), while another
    address is served;
-   ``environment=outdoor`` (the CLI's third environment) is offered.

And through the render pool itself: a render that uses its budget
(proportional to its estimate) is stopped (422) and its render process
serves the next one.
"""

from __future__ import annotations

import asyncio
import math
import os
import threading
import time
from pathlib import Path

import httpx
import loopback
import pytest

from conftest import server_process

pytestmark = [pytest.mark.slow, pytest.mark.server, pytest.mark.gl]
API = "/api/v1"
ROUGH_COATED_REFERENCE = {"roughness": 0.3, "mode": "coated", "coat_roughness": 0.1, "compare": "reference"}


def wait_for_previews(http: httpx.Client, count: int, limit_s: float) -> None:
    start = time.monotonic()
    while http.get("/healthz").json()["previews_in_flight"] != count:
        assert time.monotonic() - start < limit_s, f"previews in flight never reached {count}"
        time.sleep(0.05)


def test_refused_up_front_admitted_by_cost_and_outdoor(tmp_path):
    from preview_shaders.preview import ENVIRONMENTS

    with (
        server_process(tmp_path / "data", COATED_JOB_CPU_LIMIT_S="5", COATED_MAX_PREVIEW_SIZE="2048") as server,
        loopback.Client(base_url=server.url, timeout=120) as http,
    ):
        fit = http.post(f"{API}/fits", json={"material": "Au"}).json()["id"]
        images = {}
        for environment in ENVIRONMENTS:  # every environment the CLI renders in, outdoor included
            answer = http.get(f"{API}/preview.png", params={"fit": fit, "size": 64, "environment": environment})
            assert answer.status_code == 200, answer.text
            assert answer.content[:4] == b"\x89PNG"
            images[environment] = answer.content
        assert len(set(images.values())) == len(ENVIRONMENTS)  # each lit by its own environment

        started = time.perf_counter()
        refused = http.get(f"{API}/preview.png", params={"fit": fit, "size": 2048, **ROUGH_COATED_REFERENCE})
        assert refused.status_code == 422, refused.text
        detail = refused.json()["detail"]
        assert "estimated at 5.9 s of CPU" in detail and "5 s (COATED_JOB_CPU_LIMIT_S)" in detail, detail
        assert time.perf_counter() - started < 1.0  # nothing was rendered

        # One client renders a 2048 px smooth view (estimated 2.3 s); with a 1448 px rough one (2.9 s): 5.2 s.
        first: list = []
        thread = threading.Thread(
            target=lambda: first.append(
                loopback.get(
                    f"{server.url}{API}/preview.png", params={"fit": fit, "size": 2048, "eta_i": 1.5}, timeout=120
                )
            )
        )
        thread.start()
        wait_for_previews(http, 1, 60)
        rough = {"fit": fit, "size": 1448, "eta_i": 1.6, "roughness": 0.3}
        second = http.get(f"{API}/preview.png", params=rough)
        other_address = httpx.HTTPTransport(local_address="127.0.0.2", verify=loopback.TLS)
        with httpx.Client(base_url=server.url, timeout=120, transport=other_address) as other:
            served = other.get(f"{API}/preview.png", params={"fit": fit, "size": 256, "eta_i": 1.7})
        thread.join(120)
        assert second.status_code == 503, second.text
        assert "would pass its share, 5 s (COATED_JOB_CPU_LIMIT_S)" in second.json()["detail"]
        assert int(second.headers["retry-after"]) >= 1
        assert served.status_code == 200, served.text
        assert first[0].status_code == 200, first[0].text
        wait_for_previews(http, 0, 30)
        assert http.get(f"{API}/preview.png", params=rough).status_code == 200  # alone, within its share


def test_a_render_past_its_budget_is_stopped_and_its_process_serves_the_next():
    from service.runtime.budget import RENDER_BUDGET_FLOOR_S, RenderBudgetExceeded
    from service.runtime.previews import PreviewRunner

    def cpu_s(pid: int) -> float:  # the process's user and system CPU time (proc(5): fields 14, 15)
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    async def scenario() -> tuple[float, int, int, int]:
        runner = PreviewRunner(1, timeout_s=300, cpu_limit_s=60)
        try:
            assert await runner.preview(("warm",), math.sqrt, 4.0, cost_s=0.01) == 2.0
            pid = runner._processes[0].pid
            before = cpu_s(pid)
            with pytest.raises(RenderBudgetExceeded, match=r"CPU budget of 2\.0 s \(3 x its estimated 0\.01 s"):
                await runner.preview(("spin",), exec, "while True: pass", cost_s=0.01)  # noqa: S102 (a CPU burner)
            used_s = cpu_s(pid) - before
            assert await runner.preview(("after",), math.sqrt, 9.0, cost_s=0.01) == 3.0
            return used_s, pid, runner._processes[0].pid, runner.restarts
        finally:
            runner.close()

    used_s, pid, pid_after, restarts = asyncio.run(scenario())
    assert RENDER_BUDGET_FLOOR_S <= used_s < 10, used_s  # stopped at its budget, not at the 60 s limit
    assert (pid_after, restarts) == (pid, 0)  # the same render process, not a new one
