"""
The service on SQLite and on PostgreSQL, side by side in one run
================================================================

Starts two real ``python -m service`` processes at once, one on SQLite (a
fresh data directory) and one on a throwaway PostgreSQL server
(``tests/postgres_server.py``), each with ``--workers`` fit workers (default
every CPU), and measures both in turns, so that the machine's drifting load
lands on both alike:

-   ``--latency-fits`` REST fits of unseen n, k, one client, on each store
    in turn, fit by fit: the wall time and the CPU the server's process
    tree spent on each against the CPU of the bare fit of the same data
    (:func:`benchmarks.service_load.fit_latencies`);
-   ``--evaluations`` of those fits' metrics asked for (``GET /fits/{id}``):
    the CPU of an evaluation, which the REST fit no longer carries;
-   ``--rounds`` rounds of ``--duration`` seconds of ``--fit-clients``
    closed-loop clients POSTing new n, k fits (as ``service_load.py``), on
    each store in turn (the order swapped every round): fits answered 201
    per second of each store, and the ratio of the two.

Records benchmarks/results/service_stores.json (``figures``: per store
``fits_per_s``, ``rounds`` (each round's rate), ``refused``,
``rest_fit_unseen_ms`` and ``rest_fit_cpu``; ``postgresql_over_sqlite``:
the ratio of the rates) and prints a table.

Usage::

    .venv/bin/python benchmarks/service_stores.py [--fit-clients 16] [--duration 15] [--rounds 2]
        [--latency-fits 30] [--workers N]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.service_cpu import cpu_figures, evaluation_cpu, fit_latencies  # noqa: E402
from benchmarks.serve import start_replicas  # noqa: E402
from benchmarks.service_load import post_fits, unseen_fit_bodies  # noqa: E402

STORES = ("sqlite", "postgresql")


def load_round(url: str, clients: int, seconds: float, tag: str) -> tuple[dict, float]:
    """``clients`` closed-loop fit clients for ``seconds``: (answers by status, seconds elapsed)."""
    stop, lock = threading.Event(), threading.Lock()
    counts: dict = {}
    saved: list[str] = []
    threads = [
        threading.Thread(target=post_fits, args=(url, f"{tag}-{i}", stop, counts, lock, saved)) for i in range(clients)
    ]
    start = time.perf_counter()
    for thread in threads:
        thread.start()
    time.sleep(seconds)
    stop.set()
    for thread in threads:
        thread.join()
    return counts, time.perf_counter() - start


def main() -> int:
    load_at_start = load_average()
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--fit-clients", type=int, default=16)
    parser.add_argument("--duration", type=float, default=15.0, help="seconds of each load round (default 15)")
    parser.add_argument("--rounds", type=int, default=2, help="load rounds per store (default 2)")
    parser.add_argument("--latency-fits", type=int, default=30, help="REST fits of unseen data per store")
    parser.add_argument("--workers", type=int, default=None, help="fit workers per service (default: every CPU)")
    parser.add_argument(
        "--evaluations",
        type=int,
        default=10,
        help="fits per store whose metrics are then asked for (their evaluation's CPU)",
    )
    args = parser.parse_args()
    workers = args.workers or os.cpu_count() or 1

    sys.path.insert(0, str(ROOT / "tests"))
    from postgres_server import PostgresServer

    postgres = PostgresServer()
    servers = {}
    try:
        with tempfile.TemporaryDirectory() as data:
            # No background evaluation: the CPU measured of a REST fit is the fit's (the evaluation's
            # own is measured apart, asked for).
            env = {**os.environ, "COATED_FIT_WORKERS": str(workers), "COATED_METRICS_IDLE_S": "0"}
            (servers["sqlite"],) = start_replicas(1, env, f"{data}/sqlite")
            (servers["postgresql"],) = start_replicas(
                1, {**env, "COATED_STORE_URL": postgres.database("bench")}, f"{data}/postgresql"
            )
            try:
                # Latency and CPU: fit by fit, each store in turn, each its own unseen data.
                bodies = unseen_fit_bodies(2 * args.latency_fits)
                measured = {store: {"wall": [], "cpu": [], "bare": [], "ids": []} for store in STORES}
                for j in range(args.latency_fits):
                    for k, store in enumerate(STORES if j % 2 == 0 else STORES[::-1]):
                        process, url = servers[store]
                        one = fit_latencies(url, [bodies[2 * j + STORES.index(store)]], process.pid)
                        for key, values in one.items():
                            measured[store][key] += values
                evaluated = {
                    store: evaluation_cpu(
                        servers[store][1], servers[store][0].pid, measured[store]["ids"][: args.evaluations]
                    )
                    for store in STORES
                }
                # Throughput: rounds in turn, the order swapped every round.
                rounds: dict[str, list] = {store: [] for store in STORES}
                for r in range(args.rounds):
                    for store in STORES if r % 2 == 0 else STORES[::-1]:
                        counts, elapsed = load_round(servers[store][1], args.fit_clients, args.duration, f"{store}{r}")
                        rounds[store].append((counts, elapsed))
                        print(
                            f"round {r + 1} {store}: {counts.get(201, 0) / elapsed:.2f} fits/s, "
                            f"load {os.getloadavg()[0]:.2f}",
                            flush=True,
                        )
            finally:
                for process, _ in servers.values():
                    process.terminate()
                for process, _ in servers.values():
                    process.wait(timeout=60)
    finally:
        postgres.close()

    figures: dict = {}
    for store in STORES:
        fits = sum(c.get(201, 0) for c, _ in rounds[store])
        seconds = sum(e for _, e in rounds[store])
        wall = np.asarray(measured[store]["wall"]) * 1e3
        figures[store] = {
            "fits_per_s": fits / seconds,
            "rounds": [c.get(201, 0) / e for c, e in rounds[store]],
            "refused": sum(c.get(503, 0) for c, _ in rounds[store]),
            "other": sum(v for c, _ in rounds[store] for k, v in c.items() if k not in (201, 503)),
            "rest_fit_unseen_ms": {
                "p50": float(np.median(wall)),
                "p90": float(np.percentile(wall, 90)),
                "max": float(wall.max()),
                "n": int(wall.size),
            },
            "rest_fit_cpu": cpu_figures(measured[store], evaluated[store]),
        }
    figures["postgresql_over_sqlite"] = figures["postgresql"]["fits_per_s"] / figures["sqlite"]["fits_per_s"]
    figures["slower_store_over_faster"] = min(figures["postgresql_over_sqlite"], 1 / figures["postgresql_over_sqlite"])
    print(
        f"\nservice on each store: {workers} fit workers each, {args.fit_clients} fit clients, "
        f"{args.rounds} x {args.duration:g} s per store in turns, machine {os.cpu_count()} CPUs"
    )
    print(
        "\n| store | fits/s (rounds) | refused 503 | REST fit p50 / p90 ms | service CPU / bare fit CPU ms "
        "(p50) | ratio p50 / p90 | evaluation CPU ms (p50) |"
    )
    print("|---|---|---|---|---|---|---|")
    for store in STORES:
        f = figures[store]
        c = f["rest_fit_cpu"]
        print(
            f"| {store} | {f['fits_per_s']:.2f} ({', '.join(f'{x:.1f}' for x in f['rounds'])}) | "
            f"{f['refused']} | {f['rest_fit_unseen_ms']['p50']:.0f} / {f['rest_fit_unseen_ms']['p90']:.0f} | "
            f"{c['service_ms_p50']:.1f} / {c['bare_ms_p50']:.1f} | {c['ratio_p50']:.2f} / {c['ratio_p90']:.2f} | "
            f"{c['evaluation_ms_p50']:.1f} |"
        )
    print(f"\nPostgreSQL / SQLite fits per second: {figures['postgresql_over_sqlite']:.3f}")
    print(
        "recorded:",
        write_result(
            "service_stores",
            figures,
            load_at_start,
            workers=workers,
            fit_clients=args.fit_clients,
            rounds=args.rounds,
            duration_s=args.duration,
        ),
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
