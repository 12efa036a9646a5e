"""
Code and docs speak to users and readers of the code, not to a tracker they
cannot see: no "issue 21" (or "issues 19-25", "Issue 10, item 6") anywhere
in the packages, the browser code, the scripts or the documentation. The
history of why a change was made is in the commit messages. An upstream
project's tracker, named with its project ("OpenPBR issue #225"), is a
reference a reader can follow.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("fitting", "service", "preview_shaders", "benchmarks", "static", "scripts", "docs", "tests")
SUFFIXES = {".py", ".md", ".js", ".html", ".glsl", ".frag", ".vert", ".hlsl", ".toml", ".sh"}
TRACKER = re.compile(r"\b[Ii]ssues? #?[0-9]+")
UPSTREAM = re.compile(r"\b(OpenPBR|MaterialX|three\.js|glTF|Khronos|uvicorn|CPython) issue #?[0-9]+")


def tracker_numbers(text: str) -> list[str]:
    bare = UPSTREAM.sub("", text)
    return [f"{bare.count(chr(10), 0, m.start()) + 1}: {m.group(0)}" for m in TRACKER.finditer(bare)]


def _files():
    yield ROOT / "README.md"
    for folder in FOLDERS:
        paths = []
        for parent, dirs, files in os.walk(ROOT / folder):
            dirs[:] = [d for d in dirs if d != "node_modules"]  # not walked: npm's, most of scripts/ on a fresh clone
            paths += [Path(parent, name) for name in files]
        yield from (path for path in sorted(paths) if path.suffix in SUFFIXES and path.is_file())
    for path in sorted((ROOT / "scripts").iterdir()):
        if path.is_file() and not path.suffix:
            yield path


def test_the_check_sees_a_tracker_number():
    assert tracker_numbers("the worst point (issue 21)") == ["1: issue 21"]
    assert tracker_numbers("x\nIssue 10, item 6: the CLI") == ["2: Issue 10"]
    assert tracker_numbers("OpenPBR issue #225 says so") == []


def test_no_tracker_numbers_in_code_or_docs():
    this = Path(__file__).resolve()
    wrong = [
        f"{path.relative_to(ROOT)}:{use}"
        for path in _files()
        if path.resolve() != this
        for use in tracker_numbers(path.read_text(encoding="utf-8", errors="replace"))
    ]
    assert not wrong, "\n".join(wrong)
