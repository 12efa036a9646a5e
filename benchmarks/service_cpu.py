"""
CPU of REST fits against bare fits
==================================

What the service benchmarks (``service_load.py``, ``service_stores.py``,
``export_downloads.py``) measure of a server's CPU:

-   :func:`tree_cpu`: the CPU seconds of a server and every process below it.
-   :func:`bare_fit_cpu`: the CPU of the core's own fit of a request's data.
-   :func:`fit_latencies`: REST fits one after the other, each with its wall
    time, the server's CPU on it and, right after, its bare fit's CPU.
-   :func:`evaluation_cpu`: the server's CPU on evaluating a fit's metrics when asked for.
-   :func:`cpu_figures`: those as the records' ``rest_fit_cpu``.

The servers run with ``COATED_METRICS_IDLE_S=0`` (no background evaluation), so that
each figure is the CPU of what it names: a REST fit, or an evaluation.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import httpx
import numpy as np

API = "/api/v1"


def tree_cpu(pid: int) -> float:
    """
    CPU seconds of process ``pid`` and every process below it (its workers,
    fork server): the nanosecond run time of each of their threads
    (``/proc/<pid>/task/<tid>/schedstat``), where the kernel keeps it, else
    user + system time in clock ticks (``psutil``; 10 ms steps).
    """
    import psutil

    root = psutil.Process(pid)
    total = 0.0
    for process in (root, *root.children(recursive=True)):
        try:
            tasks = os.listdir(f"/proc/{process.pid}/task")
            total += (
                sum(int(Path(f"/proc/{process.pid}/task/{tid}/schedstat").read_text().split()[0]) for tid in tasks)
                * 1e-9
            )
        except (OSError, ValueError, IndexError):
            try:
                times = process.cpu_times()
            except psutil.NoSuchProcess:
                continue
            total += times.user + times.system
    return total


def bare_fit_cpu(body: dict) -> float:
    """CPU seconds of the core's own fit of ``body`` in this process (one BLAS thread), as a worker runs it."""
    from fitting.fits.kinds import fit_model
    from fitting.optics.library import library_material
    from fitting.optics.nk import SpectralNK

    if "material" in body:
        nk = library_material(body["material"])
    else:
        nk = SpectralNK(
            *(np.asarray(body["nk"][key], dtype=np.float64) for key in ("wavelength_nm", "n", "k")),
            name=body["name"],
            source="",
        )
    start = time.process_time()
    fit_model(nk, tuple(body.get("eta_i_range", (1.0, 2.5))))
    return time.process_time() - start


_BARE_WARM: list[bool] = []  # the bare fits' imports and caches made once


def fit_latencies(url: str, bodies: list[dict], pid: int | None = None, query: str = "") -> dict[str, list[float]]:
    """
    Each of ``bodies`` POSTed in turn: the answer's wall time, and with the
    server's ``pid`` the CPU its process tree spent on it and the CPU of the
    bare fit of the same body in this process, measured right after it (the
    two take turns, so the machine's drifting load lands on both alike).
    """
    out: dict[str, list] = {"wall": [], "cpu": [], "bare": [], "ids": []}
    if pid is not None and not _BARE_WARM:
        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=1, user_api="blas")
        bare_fit_cpu({"material": "Au"})  # imports and caches
        _BARE_WARM.append(True)
    with httpx.Client(base_url=url, timeout=300) as http:
        for body in bodies:
            cpu = tree_cpu(pid) if pid is not None else 0.0
            start = time.perf_counter()
            response = http.post(f"{API}/fits{query}", json=body)
            out["wall"].append(time.perf_counter() - start)
            if pid is not None:
                out["cpu"].append(tree_cpu(pid) - cpu)
                out["bare"].append(bare_fit_cpu(body))
            if response.status_code != 201:
                raise SystemExit(f"unseen fit answered {response.status_code}: {response.text[:200]}")
            out["ids"].append(response.json()["id"])
    return out


def evaluation_cpu(url: str, pid: int, fit_ids: list[str]) -> list[float]:
    """CPU seconds of the server's tree on ``GET /fits/{id}`` of fits whose metrics are not evaluated yet."""
    out = []
    with httpx.Client(base_url=url, timeout=300) as http:
        for fit_id in fit_ids:
            cpu = tree_cpu(pid)
            response = http.get(f"{API}/fits/{fit_id}")
            out.append(tree_cpu(pid) - cpu)
            if response.status_code != 200 or not response.json()["metrics"]["evaluated"]:
                raise SystemExit(f"GET /fits/{fit_id} answered {response.status_code}: {response.text[:200]}")
    return out


def cpu_figures(measured: dict[str, list], evaluations: list[float] = ()) -> dict:
    """
    The service's CPU per REST fit against its bare fit's (ms; the ratio per
    fit, p50 and p90), and, with ``evaluations`` (:func:`evaluation_cpu`),
    the CPU of a fit's evaluation when it is asked for (``evaluation_ms_p50``).
    """
    cpu, bare = np.asarray(measured["cpu"]) * 1e3, np.asarray(measured["bare"]) * 1e3
    ratio = cpu / bare
    extra = {}
    if len(evaluations):
        ms = np.asarray(evaluations) * 1e3
        extra = {
            "evaluation_ms_p50": float(np.median(ms)),
            "evaluation_ms_max": float(ms.max()),
            "evaluations": int(ms.size),
        }
    return {
        **extra,
        "service_ms_p50": float(np.median(cpu)),
        "service_ms_p90": float(np.percentile(cpu, 90)),
        "bare_ms_p50": float(np.median(bare)),
        "bare_ms_p90": float(np.percentile(bare, 90)),
        "ratio_p50": float(np.median(ratio)),
        "ratio_p90": float(np.percentile(ratio, 90)),
        "ratio_of_medians": float(np.median(cpu) / np.median(bare)),
        "n": int(cpu.size),
    }
