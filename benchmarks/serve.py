"""
Service processes for the benchmarks
====================================

-   :func:`free_port`: a port nothing listens on now.
-   :func:`start_replicas`: ``python -m service`` processes, each on a port of its own, once all
    answer ``/healthz``; a start whose port was taken between :func:`free_port` and its bind
    (:data:`PORT_TAKEN`) is tried again on another port, :data:`PORT_TRIES` times in all.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx

ROOT = Path(__file__).resolve().parents[1]

__all__ = ["PORT_TAKEN", "PORT_TRIES", "free_port", "start_replicas"]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


PORT_TAKEN = "address already in use"
"""What a server says when its port was taken between :func:`free_port` and its bind (another
program on the machine): the start is tried again on another port, :data:`PORT_TRIES` times in all."""

PORT_TRIES = 3


def start_replicas(count: int, env: dict[str, str], data: str) -> list[tuple[subprocess.Popen, str]]:
    """
    ``count`` service processes (each its own data directory, for SQLite) once all answer /healthz.
    A start that exits because its port was taken between :func:`free_port` and its bind
    (:data:`PORT_TAKEN` in its output) is tried again on another port, :data:`PORT_TRIES` times in
    all; any other early exit, or no answer in 180 s, ends the run with the server's last output,
    every server it started killed.
    """

    def launch(i: int) -> tuple[subprocess.Popen, str, object]:
        port = free_port()
        log = tempfile.TemporaryFile()  # a file, not a pipe: a pipe nobody reads would stall the server
        process = subprocess.Popen(
            [sys.executable, "-m", "service", "--port", str(port), "--data-dir", f"{data}/{i}"],
            cwd=ROOT,
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=log,
            start_new_session=True,
        )
        return process, f"http://127.0.0.1:{port}", log

    def fail(message: str):
        for process, _, _ in starts:  # none is left running behind the failed run
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGKILL)
        raise SystemExit(message)

    starts = [launch(i) for i in range(count)]
    deadline = time.monotonic() + 180
    for i in range(count):
        tries = 1
        while True:
            process, url, log = starts[i]
            try:
                if httpx.get(f"{url}/healthz", timeout=2).status_code == 200:
                    break
            except httpx.TransportError:
                pass
            if process.poll() is not None:
                log.seek(0)
                output = log.read().decode(errors="replace")
                if tries < PORT_TRIES and PORT_TAKEN in output:
                    tries += 1
                    log.close()
                    starts[i] = launch(i)
                    continue
                fail(f"a server exited ({process.returncode}): {output[-2000:]}")
            if time.monotonic() > deadline:
                fail(f"a server did not answer /healthz in 180 s ({url})")
            time.sleep(0.2)
    for _, _, log in starts:
        log.close()
    return [(process, url) for process, url, _ in starts]
