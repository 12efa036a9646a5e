"""
Batch outputs
=============

-   :func:`write_outputs`: the pack and the report of a finished batch from
    its journal records.
-   :func:`accuracy_summary`: the distribution over the fitted pages of the
    mean Delta E of each kind and baseline.

Files written into the output directory, each atomically (a temporary file
renamed into place):

``pack.cfpk`` / ``pack.json``
    One binary pack (``docs/pack-format.md``) and its JSON view: every fitted
    page, sorted by page, then by kind in the order requested; a record is
    named by its page (``main/Au/Johnson``), with `` [kind]`` appended when
    several kinds are requested.
``report.csv`` / ``report.json``
    One row per selected page, sorted: status, reason, coverage, data range,
    mean and max Delta E 2000 of each kind and baseline; the JSON adds the
    configuration and :func:`accuracy_summary`.
``timings.csv``
    Seconds per page and the batch's wall time and pages per second. This
    is the only file that changes between two runs of the same batch: the
    four above are the same bytes for the same selection and settings,
    whatever the number of workers, the scheduler or interruptions.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import io
import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from ..models.pack import encode_pack, pack_to_json
from .kinds import decode_material

__all__ = ["OUTPUT_FILES", "accuracy_summary", "report_rows", "write_outputs"]

OUTPUT_FILES = ("pack.cfpk", "pack.json", "report.csv", "report.json", "timings.csv")


def _write(path: Path, data: bytes) -> None:
    """
    ``data`` as ``path``, atomically: a new file of a unique name in the same
    directory (``mkstemp``: ``O_CREAT | O_EXCL``, so never through a link
    planted there), synced, then renamed over ``path`` (a rename replaces a
    link at ``path`` itself, never its target).
    """
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            os.fchmod(f.fileno(), 0o644)
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _columns(kinds, baselines) -> list[str]:
    columns = ["page", "status", "reason", "coverage", "wavelength_min_nm", "wavelength_max_nm"]
    for name in (*kinds, *baselines):
        columns += [f"{name}_delta_E_mean", f"{name}_delta_E_max"]
    return columns


def report_rows(records: list[dict[str, Any]], kinds, baselines) -> list[dict[str, Any]]:
    """One flat row per record (sorted by page), the columns of ``report.csv``."""
    rows = []
    for r in sorted(records, key=lambda r: r["page"]):
        lo, hi = r["wavelength_range_nm"] or (None, None)
        row = {
            "page": r["page"],
            "status": r["status"],
            "reason": r["reason"] or "",
            "coverage": r["coverage"],
            "wavelength_min_nm": lo,
            "wavelength_max_nm": hi,
        }
        for name in (*kinds, *baselines):
            m = r["kinds"].get(name) or r["baselines"].get(name) or {}
            row[f"{name}_delta_E_mean"] = m.get("delta_E_mean")
            row[f"{name}_delta_E_max"] = m.get("delta_E_max")
        rows.append(row)
    return rows


def accuracy_summary(records: list[dict[str, Any]], kinds, baselines) -> dict[str, Any]:
    """
    Over the fitted pages, per kind and baseline: ``pages``, and the
    ``mean``, ``median``, ``p90`` and ``max`` of the per-page mean Delta E
    2000; per kind also ``beats_lazanyi_adjusted``, the fraction of pages
    whose mean Delta E is below the adjusted Lazanyi baseline's.
    """
    fitted = [r for r in sorted(records, key=lambda r: r["page"]) if r["status"] == "fitted"]
    out: dict[str, Any] = {
        "pages": len(records),
        "fitted": len(fitted),
        "skipped": sum(r["status"] == "skipped" for r in records),
        "failed": sum(r["status"] == "failed" for r in records),
        "delta_E_mean": {},
    }
    for name in (*kinds, *baselines):
        source = "kinds" if name in kinds else "baselines"
        values = np.array([r[source][name]["delta_E_mean"] for r in fitted], dtype=np.float64)
        entry: dict[str, Any] = {"pages": int(values.size)}
        if values.size:
            entry.update(
                mean=float(values.mean()),
                median=float(np.median(values)),
                p90=float(np.quantile(values, 0.9)),
                max=float(values.max()),
            )
            if source == "kinds" and "lazanyi_adjusted" in baselines:
                laz = np.array([r["baselines"]["lazanyi_adjusted"]["delta_E_mean"] for r in fitted])
                entry["beats_lazanyi_adjusted"] = float(np.mean(values < laz))
        out["delta_E_mean"][name] = entry
    return out


def _csv(rows: list[dict[str, Any]], columns: list[str]) -> bytes:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: ("" if v is None else repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    return buffer.getvalue().encode("utf-8")


def write_outputs(
    directory: str | Path,
    records: list[dict[str, Any]],
    config: dict[str, Any],
    kinds: tuple[str, ...],
    baselines: tuple[str, ...],
    wall_s: float,
) -> dict[str, Any]:
    """Write :data:`OUTPUT_FILES` into ``directory``; returns the accuracy summary."""
    directory = Path(directory)
    records = sorted(records, key=lambda r: r["page"])
    materials = []
    for r in records:
        if r["status"] != "fitted":
            continue
        for kind in kinds:
            material = decode_material(r["materials"][kind])
            if len(kinds) > 1:
                material = dataclasses.replace(material, name=f"{r['page']} [{kind}]")
            materials.append(material)
    _write(directory / "pack.cfpk", encode_pack(materials))
    _write(directory / "pack.json", (pack_to_json(materials) + "\n").encode("utf-8"))
    columns = _columns(kinds, baselines)
    rows = report_rows(records, kinds, baselines)
    _write(directory / "report.csv", _csv(rows, columns))
    summary = accuracy_summary(records, kinds, baselines)
    report = {"config": config, "summary": summary, "pages": rows}
    _write(directory / "report.json", (json.dumps(report, indent=1, sort_keys=True) + "\n").encode("utf-8"))
    seconds = sum(r["seconds"] for r in records)
    timing_rows = [{"page": r["page"], "seconds": round(r["seconds"], 4)} for r in records]
    text = _csv(timing_rows, ["page", "seconds"]).decode("utf-8")
    text += f"# pages {len(records)}, sum of page seconds {seconds:.1f}, wall of the last run {wall_s:.1f} s\n"
    _write(directory / "timings.csv", text.encode("utf-8"))
    return summary
