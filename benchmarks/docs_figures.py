"""
Figures the docs quote, read from the benchmarks' records
=========================================================

A page quotes a benchmark's figure with a marker right before the number::

    <!-- figure: editor_speed:drag_to_curve_ms.gentle.median_ms .0f -->41

``editor_speed`` names ``benchmarks/results/editor_speed.json`` (written by
``benchmarks/editor_speed.py`` with its command, date and load average,
:mod:`benchmarks.record`), the dotted path a value in it (under its
``figures`` unless the record's top level has the first key; a number is a
list index), ``.0f`` the format the page prints it with. The marker is an
HTML comment (invisible on the rendered page); bold (``**41**``) may sit
between it and the number.

-   :func:`figures`: every marker of a page with its recorded and quoted text.
-   :func:`stale`: the markers whose page text is not the recorded figure.
-   ``python -m benchmarks.docs_figures [--write] [PAGE ...]``: list the
    stale figures of README.md and docs/*.md (exit 1 if any), or rewrite
    them from the records.
"""

from __future__ import annotations

import argparse
import functools
import json
import re
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
MARKER = re.compile(
    r"<!-- figure: (?P<name>[\w-]+):(?P<path>[^ ]+) (?P<format>[^ ]*) -->(?P<bold>\**)"
    r"(?P<number>-?[0-9]+(?:,[0-9]{3})*(?:\.[0-9]+)?)"  # "1,024", not the comma after "22, 8"
)

__all__ = ["MARKER", "pages", "recorded", "figures", "stale", "rewrite"]


def pages() -> list[Path]:
    """README.md and every page of docs/."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def recorded(name: str, path: str) -> Any:
    """The value at ``path`` in ``benchmarks/results/<name>.json``; ``LookupError`` naming what is missing."""
    file = RESULTS / f"{name}.json"
    if not file.is_file():
        raise LookupError(f"no record {file.relative_to(ROOT)}")
    stat = file.stat()
    value: Any = _record(file, stat.st_mtime_ns, stat.st_size)
    parts = path.split(".")
    if isinstance(value, dict) and parts[0] not in value and isinstance(value.get("figures"), dict):
        value = value["figures"]  # the record's named figures (benchmarks.record.write_result)
    for part in parts:
        try:
            value = value[int(part)] if isinstance(value, list) else value[part]
        except (KeyError, IndexError, ValueError, TypeError):
            raise LookupError(f"{file.relative_to(ROOT)} has no {path!r} (at {part!r})") from None
    return value


@functools.lru_cache(maxsize=16)
def _record(file: Path, mtime_ns: int, size: int) -> Any:
    """A record parsed once while it is unchanged (docs/exports.md quotes exports_seen 454 times); read only."""
    return json.loads(file.read_text())


def figures(text: str) -> list[dict[str, Any]]:
    """Every marker of ``text``: its line, key, format, the quoted number and the recorded one (or the error)."""
    out = []
    for match in MARKER.finditer(text):
        item = {
            "line": text.count("\n", 0, match.start()) + 1,
            "key": f"{match['name']}:{match['path']}",
            "format": match["format"],
            "quoted": match["number"],
            "span": match.span("number"),
        }
        try:
            item["recorded"] = format(recorded(match["name"], match["path"]), match["format"])
        except (LookupError, ValueError, TypeError) as error:
            item["error"] = str(error)
        out.append(item)
    return out


def stale(text: str) -> list[dict[str, Any]]:
    """The markers of ``text`` whose number is not the recorded figure (or whose record is missing)."""
    return [f for f in figures(text) if "error" in f or f["quoted"] != f["recorded"]]


def rewrite(text: str) -> str:
    """``text`` with every marked number replaced by its recorded figure."""
    for item in reversed(figures(text)):
        if "error" not in item:
            start, end = item["span"]
            text = text[:start] + item["recorded"] + text[end:]
    return text


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="the docs' benchmark figures against the records")
    parser.add_argument("--write", action="store_true", help="rewrite the marked figures from the records")
    parser.add_argument("pages", nargs="*", type=Path)
    args = parser.parse_args(argv)
    bad = 0
    for page in args.pages or pages():
        text = page.read_text(encoding="utf-8")
        if args.write:
            page.write_text(rewrite(text), encoding="utf-8")
            text = page.read_text(encoding="utf-8")
        for item in stale(text):
            bad += 1
            print(
                f"{page}:{item['line']}: {item['key']}: quoted {item['quoted']}, "
                f"recorded {item.get('recorded', item.get('error'))}"
            )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
