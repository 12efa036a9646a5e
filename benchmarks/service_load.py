"""
Load benchmark of the HTTP service
==================================

Starts a real ``python -m service`` on a free loopback port with a fresh
data directory, then runs a bounded load generator against it:

-   ``--fit-clients`` closed-loop clients that each POST a new fit (inline
    n, k with a unique name, so every request is a real fit, never a store
    hit) back to back for ``--duration`` seconds;
-   ``--readers`` closed-loop clients that download the binary pack of a
    stored fit at the same time.

First, one client alone POSTs ``--latency-fits`` fits of data the service has
not seen, one after the other: half a library metal over a new eta_i range,
half an upload of perturbed n, k (answered once saved; the evaluation of
the metrics on the paper's grid runs later, when asked for or when the pool
is idle). For each it measures the CPU the server's process tree spent
(``psutil``, the server and its workers) and, right after, the CPU of the
bare fit of the same data in the benchmark's own process (one BLAS thread,
as a worker): ``rest_fit_cpu`` records both and their ratio.

Prints one table: the REST fit latency of unseen data (first, p50, p90),
fits per second (answered 201), 503 refusals, and the latency percentiles of
pack downloads with no fits running (idle) and while the fits run (under
load). Then a burst: ``--burst`` (200) fits posted at
once (each its own connection), while a *separate process* (``--probe``)
times ``/healthz`` and pack downloads back to back; their p99 is the number
the issue asks for (target < 100 ms).

With ``--store postgresql`` the service runs on a throwaway PostgreSQL
server (``tests/postgres_server.py``: the installed binaries, a temporary
directory, a free loopback port) and ``--replicas N`` starts N service
processes on it (``--workers`` each; default the CPUs shared among them);
fit clients and pack readers are spread over the replicas round robin. At
the end every fit answered 201 is looked up in every replica's listing:
the table says whether all are listed by all, and how many are listed twice.

Usage::

    .venv/bin/python benchmarks/service_load.py [--duration 20] [--fit-clients 4]
        [--readers 2] [--workers N] [--metrics-samples 100] [--burst 200] [--latency-fits 40]
        [--store sqlite|postgresql] [--replicas 1]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import httpx
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
API = "/api/v1"

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.service_cpu import cpu_figures, fit_latencies  # noqa: E402
from benchmarks.serve import start_replicas  # noqa: E402


def nk_body(name: str) -> dict:
    """A smooth gold-like n, k over 350-850 nm."""
    wavelength = np.linspace(350.0, 850.0, 26)
    n = 0.2 + 1.3 * np.exp(-(((wavelength - 350.0) / 150.0) ** 2))
    k = 1.8 + 4.0 * (wavelength - 350.0) / 500.0
    return {"name": name, "nk": {"wavelength_nm": wavelength.tolist(), "n": n.tolist(), "k": k.tolist()}}


def percentiles(samples: list[float]) -> tuple[float, float, float, float]:
    ms = np.asarray(samples) * 1e3
    return tuple(float(np.percentile(ms, q)) for q in (50, 95, 99)) + (float(ms.max()),)


def unseen_fit_bodies(count: int) -> list[dict]:
    """Fits the service cannot have stored: library metals over new eta_i ranges, perturbed uploads."""
    metals = ("Au", "Cu", "Ag", "Al", "Cr", "Ni", "W", "Pd")
    rng = np.random.default_rng(14)
    bodies = []
    for j in range(count):
        if j % 2 == 0:
            lo = round(1.0 + 0.01 * (j // 2 % 50), 3)
            hi = round(lo + 0.6 + 0.01 * (j % 37), 3)
            bodies.append({"material": metals[j // 2 % len(metals)], "eta_i_range": [lo, min(hi, 3.0)]})
        else:
            body = nk_body(f"unseen {j}")
            body["nk"]["n"] = (np.asarray(body["nk"]["n"]) * (1.0 + 0.02 * rng.random(26))).tolist()
            bodies.append(body)
    return bodies


def read_packs(url: str, fit_id: str, stop: threading.Event, out: list[float]) -> None:
    with httpx.Client(base_url=url, timeout=60) as http:
        while not stop.is_set():
            start = time.perf_counter()
            response = http.get(f"{API}/fits/{fit_id}/pack")
            elapsed = time.perf_counter() - start
            response.raise_for_status()
            out.append(elapsed)


def post_fits(
    url: str, client: int, stop: threading.Event, counts: dict, lock: threading.Lock, saved: list[str]
) -> None:
    with httpx.Client(base_url=url, timeout=300) as http:
        j = 0
        while not stop.is_set():
            response = http.post(f"{API}/fits", json=nk_body(f"load {client}-{j}"))
            j += 1
            with lock:
                counts[response.status_code] = counts.get(response.status_code, 0) + 1
                if response.status_code == 201:
                    saved.append(response.json()["material_id"])
            if response.status_code == 503:
                time.sleep(float(response.headers.get("retry-after", "1")))


def probe(url: str, fit_id: str, seconds: float) -> int:
    """Separate process: time /healthz and a pack download back to back; print JSON."""
    out: dict[str, list[float]] = {"healthz": [], "pack": []}
    errors = 0
    with httpx.Client(base_url=url, timeout=30) as http:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            for key, path in (("healthz", "/healthz"), ("pack", f"{API}/fits/{fit_id}/pack")):
                start = time.perf_counter()
                response = http.get(path)
                out[key].append(time.perf_counter() - start)
                errors += response.status_code != 200
    print(json.dumps({**out, "errors": errors}))
    return 0


def burst(url: str, fit_id: str, count: int) -> tuple[dict, dict, float]:
    """``count`` fits posted at once while a separate process probes; (probe, status counts, s)."""
    prober = subprocess.Popen(
        [sys.executable, __file__, "--probe", url, fit_id, "--duration", "12"], stdout=subprocess.PIPE, text=True
    )
    time.sleep(1.0)  # the probe runs before, during and after the burst
    counts: dict = {}
    lock = threading.Lock()
    start_gate = threading.Barrier(count)

    def one(i: int) -> None:
        with httpx.Client(base_url=url, timeout=300) as http:
            start_gate.wait()
            try:
                answer = http.post(f"{API}/fits", json=nk_body(f"burst {i}")).status_code
            except httpx.TransportError as error:  # a connection refused or reset counts, by its kind
                answer = type(error).__name__
            with lock:
                counts[answer] = counts.get(answer, 0) + 1

    threads = [threading.Thread(target=one, args=(i,)) for i in range(count)]
    start = time.perf_counter()
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    elapsed = time.perf_counter() - start
    result = json.loads(prober.communicate(timeout=120)[0])
    return result, counts, elapsed


def listing(url: str) -> list[str]:
    """The ids of every saved material a replica lists (all pages)."""
    ids, cursor = [], None
    with httpx.Client(base_url=url, timeout=60) as http:
        while True:
            params = [("kind", "curves"), ("kind", "nk"), *([] if cursor is None else [("cursor", cursor)])]
            page = http.get(f"{API}/materials", params=params).json()
            ids += [m["id"] for m in page["materials"] if m["kind"] != "library"]
            cursor = page["next_cursor"]
            if cursor is None:
                return ids


def main() -> int:
    if len(sys.argv) > 1 and sys.argv[1] == "--probe":
        return probe(sys.argv[2], sys.argv[3], float(sys.argv[5]))
    load_at_start = load_average()
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--duration", type=float, default=20.0, help="seconds of load (default 20)")
    parser.add_argument("--idle", type=float, default=5.0, help="seconds of idle pack reads (default 5)")
    parser.add_argument("--fit-clients", type=int, default=4)
    parser.add_argument("--readers", type=int, default=2)
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="fit workers per replica (default: the CPUs shared among the replicas)",
    )
    parser.add_argument("--store", choices=("sqlite", "postgresql"), default="sqlite")
    parser.add_argument("--replicas", type=int, default=1, help="service processes (PostgreSQL store only)")
    parser.add_argument("--metrics-samples", type=int, default=100)
    parser.add_argument("--burst", type=int, default=200, help="fits posted at once (default 200)")
    parser.add_argument(
        "--latency-fits",
        type=int,
        default=40,
        help="sequential fits of unseen data for the REST fit latency (default 40)",
    )
    args = parser.parse_args()

    if args.replicas > 1 and args.store != "postgresql":
        parser.error("--replicas > 1 needs --store postgresql (replicas share one store)")
    args.workers = args.workers or max(1, (os.cpu_count() or 1) // args.replicas)
    postgres = None
    with tempfile.TemporaryDirectory() as data:
        # No background evaluation of the metrics: each figure is the CPU of what it names.
        env = {
            **os.environ,
            "COATED_FIT_WORKERS": str(args.workers),
            "COATED_METRICS_SAMPLES": str(args.metrics_samples),
            "COATED_METRICS_IDLE_S": "0",
        }
        if args.store == "postgresql":
            sys.path.insert(0, str(ROOT / "tests"))
            from postgres_server import PostgresServer

            postgres = PostgresServer()
            env["COATED_STORE_URL"] = postgres.database("bench")
        servers = start_replicas(args.replicas, env, data)
        urls = [url for _, url in servers]
        url = urls[0]
        try:
            measured = fit_latencies(url, unseen_fit_bodies(args.latency_fits), servers[0][0].pid)
            latency = measured["wall"]
            fit_id = httpx.post(f"{url}{API}/fits", json={"material": "Au"}, timeout=120).json()["id"]
            saved: list[str] = []

            def run(seconds: float, fit_clients: int) -> tuple[list[float], dict, float]:
                stop, lock = threading.Event(), threading.Lock()
                latencies: list[float] = []
                counts: dict = {}
                threads = [
                    threading.Thread(target=read_packs, args=(urls[i % len(urls)], fit_id, stop, latencies))
                    for i in range(args.readers)
                ]
                threads += [
                    threading.Thread(target=post_fits, args=(urls[i % len(urls)], i, stop, counts, lock, saved))
                    for i in range(fit_clients)
                ]
                start = time.perf_counter()
                for thread in threads:
                    thread.start()
                time.sleep(seconds)
                stop.set()
                for thread in threads:
                    thread.join()
                return latencies, counts, time.perf_counter() - start

            idle, _, _ = run(args.idle, 0)
            loaded, counts, elapsed = run(args.duration, args.fit_clients)
            listings = [listing(u) for u in urls]
            probed, burst_counts, burst_s = burst(url, fit_id, args.burst) if args.burst else ({}, {}, 0.0)
        finally:
            for process, _ in servers:
                process.terminate()
            for process, _ in servers:
                process.wait(timeout=60)
            if postgres is not None:
                postgres.close()

    fits = counts.get(201, 0)
    print(
        f"service load: {args.workers} fit workers, {args.fit_clients} fit clients, "
        f"{args.readers} pack readers, {args.duration:g} s, metrics grid "
        f"{args.metrics_samples}x{args.metrics_samples}, machine {os.cpu_count()} CPUs, "
        f"store {args.store}, {args.replicas} replica(s)"
    )
    print()
    print("| quantity | value |")
    print("|---|---|")
    ms = np.asarray(latency) * 1e3
    figures: dict = {"fits_per_s": fits / elapsed}
    if ms.size:
        figures["rest_fit_unseen_ms"] = {
            "first": float(ms[0]),
            "p50": float(np.percentile(ms, 50)),
            "p90": float(np.percentile(ms, 90)),
            "n": int(ms.size),
        }
        print(f"| REST fit of unseen data, one client: fits | {ms.size} |")
        print(
            f"| REST fit of unseen data: first / p50 / p90 ms | {ms[0]:.0f} / "
            f"{np.percentile(ms, 50):.0f} / {np.percentile(ms, 90):.0f} |"
        )
        figures["rest_fit_cpu"] = cpu_figures(measured)
        print(
            f"| REST fit of unseen data: service CPU / bare fit CPU ms (p50), ratio p50 / p90 | "
            f"{figures['rest_fit_cpu']['service_ms_p50']:.1f} / {figures['rest_fit_cpu']['bare_ms_p50']:.1f}, "
            f"{figures['rest_fit_cpu']['ratio_p50']:.2f} / {figures['rest_fit_cpu']['ratio_p90']:.2f} |"
        )
    print(f"| fits answered 201 | {fits} |")
    print(f"| fits per second | {fits / elapsed:.2f} |")
    print(f"| fits refused 503 (Retry-After) | {counts.get(503, 0)} |")
    print(f"| other answers | {sum(v for k, v in counts.items() if k not in (201, 503))} |")
    every = all(set(saved) <= set(ids) for ids in listings)
    twice = sum(len(ids) - len(set(ids)) for ids in listings)
    print(
        f"| saves answered 201: listed by every replica / listed twice | "
        f"{'all ' + str(len(saved)) if every else 'NOT all'} / {twice} |"
    )
    figures["saves"] = {"answered": len(saved), "listed_by_every_replica": every, "listed_twice": twice}
    for label, samples in (("idle", idle), ("under load", loaded)):
        p50, p95, p99, worst = percentiles(samples)
        print(f"| pack download {label}: requests | {len(samples)} |")
        print(f"| pack download {label}: p50 / p95 / p99 / max ms | {p50:.1f} / {p95:.1f} / {p99:.1f} / {worst:.1f} |")
        figures[f"pack_{label.replace(' ', '_')}_ms"] = {"p50": p50, "p95": p95, "p99": p99, "max": worst}
    if args.burst:
        print(
            f"| burst: {args.burst} fits at once, answers | "
            f"{', '.join(f'{k}: {v}' for k, v in sorted(burst_counts.items(), key=str))} ({burst_s:.1f} s) |"
        )
        for key, label in (("healthz", "/healthz"), ("pack", "pack download")):
            p50, p95, p99, worst = percentiles(probed[key])
            print(f"| burst, separate process: {label} requests | {len(probed[key])} |")
            print(
                f"| burst, separate process: {label} p50 / p95 / p99 / max ms | "
                f"{p50:.1f} / {p95:.1f} / {p99:.1f} / {worst:.1f} |"
            )
        print(f"| burst, separate process: answers other than 200 | {probed['errors']} |")
        figures["burst_p99_ms"] = {key: percentiles(probed[key])[2] for key in ("healthz", "pack")}
        figures["burst_answers"] = {str(k): v for k, v in burst_counts.items()}
    # One record per store and replica count (the PostgreSQL runs do not overwrite the SQLite one).
    name = (
        "service_load"
        if args.store == "sqlite" and args.replicas == 1
        else (f"service_load_{args.store}_{args.replicas}")
    )
    write_result(name, figures, load_at_start)
    return 0


if __name__ == "__main__":
    sys.exit(main())
