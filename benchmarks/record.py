"""
Recorded benchmark output
=========================

Every figure the docs quote comes from a benchmark's recorded output,
``benchmarks/results/<benchmark>.json``, written by the benchmark itself:
its command, the date, the CPU, the load average at the start and the end,
and the figures (``figures``: named values a page quotes through
``benchmarks/docs_figures.py``).

-   :func:`write_result`: record one run.
-   :func:`load_average`: the 1-minute load average (``os.getloadavg``).
"""

from __future__ import annotations

import json
import os
import sys
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

__all__ = ["RESULTS", "write_result", "load_average", "cpu"]

RESULTS = Path(__file__).resolve().parent / "results"


def load_average() -> float:
    return round(os.getloadavg()[0], 2)


def cpu() -> str:
    """The CPU model and core count, from /proc/cpuinfo."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return f"{line.split(':', 1)[1].strip()}, {os.cpu_count()} cores"
    except OSError:
        pass
    return f"{os.cpu_count()} cores"


def write_result(name: str, figures: dict[str, Any], load_at_start: float, **extra: Any) -> Path:
    """
    Write ``benchmarks/results/<name>.json``: the command (this process's
    arguments), the date (UTC, minutes), the CPU, the load average at the
    start and now, ``figures`` and ``extra``; returns the path.
    """
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.json"
    path.write_text(
        json.dumps(
            {
                "command": " ".join([f"benchmarks/{Path(sys.argv[0]).name}", *sys.argv[1:]]),
                "date": datetime.now(timezone.utc).isoformat(timespec="minutes"),
                "cpu": cpu(),
                "load_average": [load_at_start, load_average()],
                "figures": figures,
                **extra,
            },
            indent=2,
        )
        + "\n"
    )
    return path
