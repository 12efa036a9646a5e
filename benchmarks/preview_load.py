"""
/healthz during previews
========================

Starts a real ``python -m service`` on a free loopback port with a fresh
data directory, fits gold, renders ``--previews`` small warm-up previews at
once (each render process is started, with its GL context, its LUT and the
prefiltered studio; before the render pool: the server's one GL thread),
then, for each
of ``--rounds`` rounds, sends ``--previews`` (2) previews at once: 1024 px,
rough (0.3) under a rough coat (``mode=coated``, coat roughness 0.1) in the
studio, split with the spectral reference (each at its own eta_i, so none
shares another's render). Meanwhile a *separate process* (``--probe``: its
own interpreter, so its timings are the server's and not this process's)
requests ``/healthz`` back to back, from ``--idle`` (5) seconds before the
first round until the last preview is answered: the idle seconds are the
control (on a shared machine, other people's work delays ``/healthz`` too).

Prints one table (``/healthz`` requests, p50 / p95 / p99 / max ms while
idle and while the previews render, the previews' statuses and seconds)
and records it in
``benchmarks/results/preview_load.json`` (:mod:`benchmarks.record`). Issue
20, item 8: ``/healthz`` is always answered fast while previews render.

Usage::

    .venv/bin/python benchmarks/preview_load.py [--rounds 1] [--previews 2] [--size 1024]
        [--name preview_load]
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

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
API = "/api/v1"

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.serve import start_replicas  # noqa: E402
from benchmarks.service_load import percentiles  # noqa: E402

ROUGH_COATED_REFERENCE = {
    "roughness": 0.3,
    "mode": "coated",
    "coat_roughness": 0.1,
    "environment": "studio",
    "compare": "reference",
}
"""The preview of the issue's measurement: rough, coated, split with the spectral reference."""


def probe(url: str, stop_file: str, limit_s: float) -> int:
    """Separate process: /healthz back to back until ``stop_file`` exists (or ``limit_s``); print JSON."""
    out: list[tuple[float, float]] = []  # (wall-clock time sent, seconds)
    errors = 0
    with httpx.Client(base_url=url, timeout=30) as http:
        deadline = time.monotonic() + limit_s
        while not os.path.exists(stop_file) and time.monotonic() < deadline:
            sent, start = time.time(), time.perf_counter()
            response = http.get("/healthz")
            out.append((sent, time.perf_counter() - start))
            errors += response.status_code != 200
    print(json.dumps({"healthz": out, "errors": errors}))
    return 0


def previews_at_once(url: str, fit_id: str, count: int, size: int, round_: int) -> list[tuple[int, float]]:
    """``count`` rough coated reference previews at once, each at its own eta_i; (status, s) each."""
    results: list[tuple[int, float]] = [(0, 0.0)] * count

    def one(i: int) -> None:
        params = {
            "fit": fit_id,
            "size": size,
            "eta_i": round(1.3 + 0.1 * i + 0.01 * round_, 3),
            **ROUGH_COATED_REFERENCE,
        }
        with httpx.Client(base_url=url, timeout=600) as http:
            start = time.perf_counter()
            response = http.get(f"{API}/preview.png", params=params)
            results[i] = (response.status_code, time.perf_counter() - start)

    threads = [threading.Thread(target=one, args=(i,)) for i in range(count)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return results


def main() -> int:
    if len(sys.argv) > 1 and sys.argv[1] == "--probe":
        return probe(sys.argv[2], sys.argv[3], float(sys.argv[4]))
    load_at_start = load_average()
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--rounds", type=int, default=1, help="rounds of previews at once (default 1)")
    parser.add_argument("--previews", type=int, default=2, help="previews at once (default 2)")
    parser.add_argument("--size", type=int, default=1024, help="pixels per side (default 1024)")
    parser.add_argument("--idle", type=float, default=5.0, help="seconds probed before the previews (default 5)")
    parser.add_argument("--name", default="preview_load", help="the record's name (default preview_load)")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as data:
        env = {
            **os.environ,
            "COATED_FIT_WORKERS": "1",
            "COATED_METRICS_SAMPLES": "30",
            "COATED_MAX_PREVIEWS_IN_FLIGHT": str(args.previews),
        }
        [(server, url)] = start_replicas(1, env, data)
        try:
            fit_id = httpx.post(f"{url}{API}/fits", json={"material": "Au"}, timeout=120).json()["id"]
            warm = previews_at_once(url, fit_id, args.previews, 64, -1)
            if any(status != 200 for status, _ in warm):
                raise SystemExit(f"the warm-up previews answered {warm}")
            stop_file = os.path.join(data, "stop")
            prober = subprocess.Popen(
                [sys.executable, __file__, "--probe", url, stop_file, "900"], stdout=subprocess.PIPE, text=True
            )
            time.sleep(args.idle)  # the control: the probe alone
            answers = []
            started, since = time.perf_counter(), time.time()
            for round_ in range(args.rounds):
                answers += previews_at_once(url, fit_id, args.previews, args.size, round_)
            wall = time.perf_counter() - started
            Path(stop_file).touch()
            probed = json.loads(prober.communicate(timeout=120)[0])
        finally:
            server.terminate()
            server.wait(timeout=60)
    idle = [seconds for sent, seconds in probed["healthz"] if sent < since]
    during = [seconds for sent, seconds in probed["healthz"] if sent >= since]
    p50, p95, p99, worst = percentiles(during)
    i50, i95, i99, iworst = percentiles(idle)
    seconds = [s for _, s in answers]
    statuses: dict[str, int] = {}
    for status, _ in answers:
        statuses[str(status)] = statuses.get(str(status), 0) + 1
    print(
        f"previews and /healthz: {args.rounds} round(s) of {args.previews} previews at once, "
        f"{args.size} px rough coated reference, machine {os.cpu_count()} CPUs, load {load_at_start}\n"
    )
    print("| quantity | value |\n|---|---|")
    print(f"| previews answered | {', '.join(f'{k}: {v}' for k, v in sorted(statuses.items()))} |")
    print(f"| preview seconds (min / max) | {min(seconds):.1f} / {max(seconds):.1f} |")
    print(f"| /healthz idle, no previews: requests | {len(idle)} |")
    print(f"| /healthz idle: p50 / p95 / p99 / max ms | {i50:.1f} / {i95:.1f} / {i99:.1f} / {iworst:.1f} |")
    print(f"| /healthz during the previews: requests | {len(during)} |")
    print(
        f"| /healthz during the previews: p50 / p95 / p99 / max ms | {p50:.1f} / {p95:.1f} / {p99:.1f} / {worst:.1f} |"
    )
    print(f"| /healthz answers other than 200 | {probed['errors']} |")
    figures = {
        "healthz_ms": {"p50": p50, "p95": p95, "p99": p99, "max": worst},
        "healthz_requests": len(during),
        "healthz_errors": probed["errors"],
        "idle_healthz_ms": {"p50": i50, "p95": i95, "p99": i99, "max": iworst},
        "idle_healthz_requests": len(idle),
        "preview_statuses": statuses,
        "preview_s": {"min": min(seconds), "max": max(seconds)},
        "wall_s": wall,
    }
    path = write_result(
        args.name,
        figures,
        load_at_start,
        rounds=args.rounds,
        previews=args.previews,
        size=args.size,
        preview=ROUGH_COATED_REFERENCE,
        loadavg=Path("/proc/loadavg").read_text().strip(),
    )
    print(f"\nrecorded in {path.relative_to(ROOT)}")
    return 0 if set(statuses) == {"200"} else 1


if __name__ == "__main__":
    raise SystemExit(main())
