"""
Export downloads through a real server: the first and the repeated
=================================================================

Starts a real ``python -m service`` (fresh data directory), fits
``--materials`` (library conductors), then downloads each fit's export in
every format (mtlx, openpbr, blender, gltf) at each ``--eta-i``: once (the
export is made: its tools' values fitted in a worker) and ``--repeats``
times more (the same download: the service keeps what it derived from the
fit, :mod:`service.derived`). For each download it measures the wall time
one client sees and the CPU the server's process tree spent on it
(``psutil``).

Records benchmarks/results/export_downloads.json (``figures``: ``first``
and ``repeated``, each with the wall ``p50_ms``, ``p90_ms``, ``max_ms`` and
the server's CPU ``cpu_p50_ms``, ``cpu_max_ms``; ``downloads``, how many of
each; ``first_by_format``: the first downloads' server CPU ``cpu_p50_ms``,
``cpu_max_ms`` per format) and prints a table.

Usage: .venv/bin/python benchmarks/export_downloads.py [--materials Au,Cu,Ag] [--eta-i 1.0,1.5] [--repeats 20]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import httpx
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.service_cpu import tree_cpu  # noqa: E402
from benchmarks.serve import start_replicas  # noqa: E402

API = "/api/v1"
FORMATS = ("mtlx", "openpbr", "blender", "gltf")


def stats(wall: list[float], cpu: list[float]) -> dict:
    w, c = np.asarray(wall) * 1e3, np.asarray(cpu) * 1e3
    return {
        "p50_ms": float(np.median(w)),
        "p90_ms": float(np.percentile(w, 90)),
        "max_ms": float(w.max()),
        "cpu_p50_ms": float(np.median(c)),
        "cpu_max_ms": float(c.max()),
        "downloads": int(w.size),
    }


def main() -> int:
    load_at_start = load_average()
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--materials", default="Au,Cu,Ag")
    parser.add_argument("--eta-i", default="1.0,1.5")
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    materials, etas = args.materials.split(","), [float(e) for e in args.eta_i.split(",")]
    first: dict[str, list[float]] = {"wall": [], "cpu": []}
    repeated: dict[str, list[float]] = {"wall": [], "cpu": []}
    first_cpu: dict[str, list[float]] = {fmt: [] for fmt in FORMATS}
    with tempfile.TemporaryDirectory() as data:
        ((process, url),) = start_replicas(1, {**os.environ, "COATED_METRICS_IDLE_S": "0"}, data)
        try:
            with httpx.Client(base_url=url, timeout=300) as http:
                for material in materials:
                    fit_id = http.post(f"{API}/fits", json={"material": material}).json()["id"]
                    for eta in etas:
                        for fmt in FORMATS:
                            path = f"{API}/fits/{fit_id}/pack?format={fmt}&eta_i={eta:g}"
                            for k in range(1 + args.repeats):
                                cpu = tree_cpu(process.pid)
                                start = time.perf_counter()
                                response = http.get(path)
                                wall = time.perf_counter() - start
                                response.raise_for_status()
                                into = first if k == 0 else repeated
                                into["wall"].append(wall)
                                into["cpu"].append(tree_cpu(process.pid) - cpu)
                                if k == 0:
                                    first_cpu[fmt].append(into["cpu"][-1])
                        print(
                            f"{material} eta_i {eta:g}: first {1e3 * np.median(first['wall'][-4:]):.0f} ms, "
                            f"repeated {1e3 * np.median(repeated['wall'][-4 * args.repeats :]):.1f} ms "
                            f"(medians), load {os.getloadavg()[0]:.2f}",
                            flush=True,
                        )
        finally:
            process.terminate()
            process.wait(timeout=60)
    figures = {
        "first": stats(first["wall"], first["cpu"]),
        "repeated": stats(repeated["wall"], repeated["cpu"]),
        "first_by_format": {
            fmt: {"cpu_p50_ms": float(1e3 * np.median(c)), "cpu_max_ms": float(1e3 * max(c))}
            for fmt, c in first_cpu.items()
        },
    }
    print("\n| download | p50 / p90 / max ms | server CPU p50 / max ms | downloads |")
    print("|---|---|---|---|")
    for name, f in figures.items():
        if name == "first_by_format":
            continue
        print(
            f"| {name} | {f['p50_ms']:.1f} / {f['p90_ms']:.1f} / {f['max_ms']:.1f} | "
            f"{f['cpu_p50_ms']:.1f} / {f['cpu_max_ms']:.1f} | {f['downloads']} |"
        )
    print(
        "first, server CPU p50 / max ms:",
        ", ".join(
            f"{fmt} {f['cpu_p50_ms']:.0f} / {f['cpu_max_ms']:.0f}" for fmt, f in figures["first_by_format"].items()
        ),
    )
    print(
        "recorded:",
        write_result(
            "export_downloads",
            figures,
            load_at_start,
            materials=materials,
            eta_i=etas,
            formats=list(FORMATS),
            repeats=args.repeats,
        ),
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
