"""
The editor's ES modules under ``node --test`` (tests/static/js/*.test.mjs):
the state and its named actions, the refit pipeline (coalescing, live vs
full refits, stale answers dropped, 503 retries), the figures read from a
fit and the browser's model kinds. The modules are the files the service
serves (static/), imported as they are, with no build step; this test
fails when node reports a failure, or when no test ran.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # starts a process (node)

ROOT = Path(__file__).resolve().parents[2]
TESTS = sorted((ROOT / "tests" / "static" / "js").glob("*.test.mjs"))


def test_editor_modules_pass_node_test():
    node = shutil.which("node")
    assert node, "node is needed for the editor's unit tests (docs/testing.md)"
    assert TESTS, "no tests/static/js/*.test.mjs"
    done = subprocess.run([node, "--test", *map(str, TESTS)], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    report = done.stdout + done.stderr
    assert done.returncode == 0, report[-4000:]
    passed = re.search(r"^# pass (\d+)", report, re.M)
    failed = re.search(r"^# fail (\d+)", report, re.M)
    assert passed and int(passed.group(1)) >= 15 and failed and failed.group(1) == "0", report[-4000:]
