"""
Speed against error: summaries, tables and figures
==================================================

The pure half of ``benchmarks/speed_vs_error.py``: what it measured, turned
into Markdown tables. Nothing here times or fits anything, so the
tests run it on small inputs (``tests/benchmarks/test_speed_vs_error.py``).

-   :func:`run_header`: the command, the date and the load average of a run;
    :func:`load_average`: the load average now.
-   :func:`error_summary`: Delta E 2000 maps per conductor to the mean of the
    means, the largest sample and the worst conductor.
-   :func:`pareto_front`: the names not dominated in (cost, error).
-   :func:`models_table`, :func:`split_sum_table_lines`: the Fresnel models
    and the split-sum variants, error and cost, with their fronts.
-   :func:`read_batch_report`: a ``python -m fitting batch`` ``report.json``.
-   :func:`batch_rows`, :func:`batch_table`: its accuracy summary (per model
    kind and baseline, the distribution of the per-page mean Delta E 2000
    and the share of pages beating adjusted Lazanyi).
-   :func:`batch_cell`: one kind's distribution in one table cell.
-   :func:`kinds_table`: every model kind side by side: cost, error against
    the spectral reference, split sum, batch distribution.
The PNGs are :mod:`benchmarks.speed_vs_error_figures`.
"""

from __future__ import annotations

import json
import os
import shlex
import time
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "run_header",
    "load_average",
    "error_summary",
    "pareto_front",
    "models_table",
    "split_sum_table_lines",
    "BATCH_BINS",
    "read_batch_report",
    "batch_label",
    "batch_rows",
    "batch_table",
    "batch_cell",
    "kinds_table",
]

BATCH_BINS = (0.0, 0.5, 1.0, 2.0, 5.0, 10.0, float("inf"))
"""Edges of the per-page mean Delta E 2000 bins of the batch table."""


def load_average() -> str:
    """The 1, 5 and 15 minute load averages, as ``uptime`` prints them."""
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def run_header(argv: list[str], renderer: str | None = None) -> list[str]:
    """Lines naming the command, the date (UTC), the load average and the cores of this run."""
    command = " ".join([".venv/bin/python benchmarks/speed_vs_error.py", *map(shlex.quote, argv)])
    lines = [
        f"Command: `{command}`",
        f"Run: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average {load_average()} "
        f"(1, 5, 15 min) at the start, {os.cpu_count()} cores",
    ]
    if renderer:
        lines[-1] += f", GL: {renderer}"
    return lines


def error_summary(per_material: dict[str, np.ndarray]) -> dict[str, Any]:
    """
    Delta E 2000 samples per conductor (any shape each) to ``mean`` (the
    mean over conductors of each one's mean), ``max`` (the largest
    sample), ``worst`` (the conductor with the largest mean) and its
    ``worst_mean`` and ``worst_max``.
    """
    if not per_material:
        raise ValueError("`per_material` must hold at least one conductor, got none")
    means = {m: float(np.mean(e)) for m, e in per_material.items()}
    maxes = {m: float(np.max(e)) for m, e in per_material.items()}
    worst = max(means, key=means.get)
    return {
        "mean": float(np.mean(list(means.values()))),
        "max": max(maxes.values()),
        "worst": worst,
        "worst_mean": means[worst],
        "worst_max": maxes[worst],
    }


def pareto_front(points: dict[str, tuple[float, float]]) -> list[str]:
    """Names not dominated in (cost, error): nothing else is no worse in both and better in one.
    Sorted by cost."""
    front = []
    for name, (cost, error) in points.items():
        dominated = any(
            (c <= cost and e <= error) and (c < cost or e < error) for other, (c, e) in points.items() if other != name
        )
        if not dominated:
            front.append(name)
    return sorted(front, key=lambda n: points[n][0])


def models_table(
    models: dict[str, tuple], rows: dict[str, dict], cpu: dict[str, float], shader: dict[str, float], pixels: int
) -> tuple[list[str], dict[str, Any]]:
    """
    The Markdown table of the Fresnel models. ``models``: name to (label,
    shader variant or None, bytes per material, how stored); ``rows``:
    :func:`error_summary` per name; ``cpu``: ns per sample; ``shader``: wall
    us per full-screen render of ``pixels`` per variant (with ``lazanyi``).
    Returns the lines and ``ratio`` (shader time relative to adjusted
    Lazanyi, None without a shader) with the fronts ``shader``, ``cpu`` and
    ``bytes``.
    """
    ratio = {m: shader[spec[1]] / shader["lazanyi"] if spec[1] else None for m, spec in models.items()}
    fronts = {
        "shader": pareto_front({m: (ratio[m], rows[m]["mean"]) for m in models if ratio[m]}),
        "cpu": pareto_front({m: (cpu[m], rows[m]["mean"]) for m in models}),
        "bytes": pareto_front({m: (models[m][2], rows[m]["mean"]) for m in models}),
    }
    lines = [
        "| model | mean dE (22) | max dE (22) | worst conductor: mean / max | shader cost vs adj. Lazanyi "
        "| shader ns/pixel | CPU ns/sample | bytes/material | on front (shader / CPU / bytes) |",
        "|---|---:|---:|---|---:|---:|---:|---:|---|",
    ]
    for m, (label, variant, size, _) in models.items():
        r = rows[m]
        cost = (f"{ratio[m]:.2f}x", f"{shader[variant] * 1e3 / pixels:.2f}") if variant else ("n/a (no shader)", "n/a")
        on = " / ".join("yes" if m in f else "no" for f in fronts.values())
        lines.append(
            f"| {label} | {r['mean']:.3f} | {r['max']:.2f} | {r['worst']}: {r['worst_mean']:.3f} / "
            f"{r['worst_max']:.2f} | {cost[0]} | {cost[1]} | {cpu[m]:.0f} | {size} | {on} |"
        )
    return lines, {"ratio": ratio, **fronts}


def split_sum_table_lines(
    variants: dict[str, tuple],
    split: dict[str, dict],
    cpu: dict[str, float],
    shader: dict[str, float],
    pixels: int,
    roughness,
) -> tuple[list[str], dict[str, Any]]:
    """
    The Markdown table of the split-sum variants. ``variants``: name to
    (label, ``ibl.frag`` pass, LUT fetches); ``split``: :func:`error_summary`
    with ``by_roughness`` (one mean per ``roughness``) per name; ``cpu``: ns
    per sample; ``shader``: wall us per full-screen pass of ``pixels``,
    with ``split_sum_lazanyi`` and ``split_sum_fixed`` (no split sum).
    Returns the lines and ``raw`` and ``net`` (the pass time relative to
    adjusted Lazanyi's split sum; net: with the fixed pass subtracted from
    both) with ``front`` (of raw cost and mean error).
    """
    fixed, base = shader["split_sum_fixed"], shader["split_sum_lazanyi"]
    raw = {v: shader[spec[1]] / base for v, spec in variants.items()}
    net = {v: (shader[spec[1]] - fixed) / (base - fixed) for v, spec in variants.items()}
    front = pareto_front({v: (raw[v], split[v]["mean"]) for v in variants})
    lines = [
        "| variant | mean dE | max dE | worst conductor: mean / max | mean dE at roughness "
        + " / ".join(f"{r:g}" for r in roughness)
        + " | shader ns/pixel | shader vs adj. Lazanyi's "
        "(raw / net) | CPU ns/sample | LUT fetches | on front (shader) |",
        "|---|---:|---:|---|---|---:|---:|---:|---:|---|",
    ]
    for v, (label, variant, fetches) in variants.items():
        r = split[v]
        lines.append(
            f"| {label} | {r['mean']:.3f} | {r['max']:.2f} | {r['worst']}: {r['worst_mean']:.3f} / "
            f"{r['worst_max']:.2f} | {' / '.join(f'{e:.3f}' for e in r['by_roughness'])} | "
            f"{shader[variant] * 1e3 / pixels:.2f} | {raw[v]:.2f}x / {net[v]:.2f}x | "
            f"{cpu[v]:.0f} | {fetches} | {'yes' if v in front else 'no'} |"
        )
    return lines, {"raw": raw, "net": net, "front": front}


def read_batch_report(path: str | Path) -> dict[str, Any]:
    """A batch ``report.json`` (docs/batch.md), with ``path`` added; ``ValueError`` naming
    the file when it is not one."""
    path = Path(path)
    report = json.loads(path.read_text(encoding="utf-8"))
    if not isinstance(report, dict):
        raise ValueError(f"`{path}` is not a batch report.json: not a JSON object")
    missing = [k for k in ("config", "summary", "pages") if k not in report]
    if missing:
        raise ValueError(f"`{path}` is not a batch report.json: no {', '.join(missing)}")
    return {**report, "path": str(path)}


def batch_label(report: dict[str, Any]) -> str:
    """A short name for a batch report: its folder and its fitted pages."""
    folder = Path(report.get("path", "batch/report.json")).parent.name
    return f"{folder} ({report['summary']['fitted']} pages)"


def batch_rows(report: dict[str, Any]) -> list[dict[str, Any]]:
    """
    One row per model kind and baseline of a batch report with fitted pages:
    ``name``, ``kind`` (True for a model kind), ``pages``, ``mean``,
    ``median``, ``p90``, ``max`` (the batch's own summary of the per-page mean
    Delta E 2000), ``shares`` (the fraction of fitted pages in each bin of
    :data:`BATCH_BINS`) and ``beats`` (the fraction beating adjusted Lazanyi;
    None for a baseline).
    """
    summary, config = report["summary"], report["config"]
    fitted = [p for p in report["pages"] if p["status"] == "fitted"]
    kinds = list(config["model_kinds"])
    rows = []
    for name in kinds + list(config["baselines"]):
        entry = summary["delta_E_mean"][name]
        if not entry["pages"]:
            continue
        values = np.array([p[f"{name}_delta_E_mean"] for p in fitted], dtype=np.float64)
        shares = np.histogram(values, bins=np.array(BATCH_BINS))[0] / values.size
        rows.append(
            {
                "name": name,
                "kind": name in kinds,
                "pages": entry["pages"],
                **{k: entry[k] for k in ("mean", "median", "p90", "max")},
                "shares": shares.tolist(),
                "beats": entry.get("beats_lazanyi_adjusted"),
            }
        )
    return rows


def batch_table(report: dict[str, Any]) -> list[str]:
    """The accuracy summary of a batch report as a heading and a Markdown table."""
    summary, config = report["summary"], report["config"]
    lo, hi = config["eta_i_range"]
    bins = [f"{a:g}-{b:g}" if b != float("inf") else f">{a:g}" for a, b in zip(BATCH_BINS[:-1], BATCH_BINS[1:])]
    lines = [
        f"## Database batch: {summary['fitted']} of {summary['pages']} pages fitted "
        f"({summary['skipped']} skipped, {summary['failed']} failed), grid {config['grid']}, "
        f"eta_i {lo:g}-{hi:g}",
        "",
        f"From `{report.get('path', 'report.json')}`. Per-page mean Delta E 2000 against the "
        f"{config.get('reference_step_nm', 1):g} nm spectral reference.",
        "",
        "| model | mean | median | p90 | max | " + " | ".join(f"share {b}" for b in bins) + " | beats adj. Lazanyi |",
        "|---|" + "---:|" * (4 + len(bins) + 1),
    ]
    for r in batch_rows(report):
        beats = "" if r["beats"] is None else format(r["beats"], ".1%")
        lines.append(
            f"| {r['name']} | {r['mean']:.3f} | {r['median']:.3f} | {r['p90']:.3f} | {r['max']:.2f} | "
            + " | ".join(f"{v:.0%}" for v in r["shares"])
            + f" | {beats} |"
        )
    return lines


def batch_cell(report: dict[str, Any], name: str) -> str:
    """``median / p90 / max`` of ``name``'s per-page mean Delta E in a batch report, and the
    share of pages where a kind beats adjusted Lazanyi; "not in this batch" when absent."""
    row = next((r for r in batch_rows(report) if r["name"] == name), None)
    if row is None:
        return "not in this batch"
    cell = f"{row['median']:.3f} / {row['p90']:.3f} / {row['max']:.2f}"
    return cell if row["beats"] is None else f"{cell}; {row['beats']:.1%}"


def kinds_table(rows: list[dict[str, Any]], reports: list[dict[str, Any]]) -> list[str]:
    """
    Every model kind side by side (and adjusted Lazanyi, the yardstick).
    Each row: ``name`` (the batch's name of the kind or baseline), ``label``,
    ``bytes``, ``mean``, ``max`` (Delta E 2000 on the 22 conductors),
    ``shader_ns_px`` and ``shader_ratio`` (full-screen evaluation, None with
    no shader), ``cpu_ns``, ``split_mean`` and ``split_ratio`` (its split sum;
    None with no split-sum table). Batch columns: one per report.
    """
    head = (
        "| model | bytes/material | mean dE (22) | max dE (22) | shader ns/pixel | shader vs adj. Lazanyi "
        "| CPU ns/sample | split sum mean dE | split-sum shader vs adj. Lazanyi's"
    )
    head += "".join(f" | batch {batch_label(b)}: median / p90 / max; beats adj. Lazanyi" for b in reports)
    lines = [head + " |", "|---|" + "---:|" * 8 + "---|" * len(reports)]
    for r in rows:
        shader = (
            ("n/a (no shader)", "n/a")
            if r["shader_ratio"] is None
            else (f"{r['shader_ns_px']:.2f}", f"{r['shader_ratio']:.2f}x")
        )
        split = (
            ("no split-sum table", "n/a")
            if r["split_mean"] is None
            else (f"{r['split_mean']:.3f}", f"{r['split_ratio']:.2f}x")
        )
        cells = [
            r["label"],
            f"{r['bytes']}",
            f"{r['mean']:.3f}",
            f"{r['max']:.2f}",
            *shader,
            f"{r['cpu_ns']:.0f}",
            *split,
            *(batch_cell(b, r["name"]) for b in reports),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return lines
