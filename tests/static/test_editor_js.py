"""
The editor's ES modules under ``node --test`` (tests/static/js/*.test.mjs):
the state and its named actions, the refit pipeline (coalescing, live vs
full refits, stale answers dropped, 503 retries), the figures read from a
fit and the browser's model kinds. The modules are the files the service
serves (static/), imported as they are, with no build step; the model
kinds are the server's ``GET /api/v1/domain`` answer, written for node to a
file named by ``COATED_DOMAIN_JSON`` (tests/static/js/domain.mjs reads it).
This test fails when node reports a failure, or when no test ran.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # starts a process (node)

ROOT = Path(__file__).resolve().parents[2]
TESTS = sorted((ROOT / "tests" / "static" / "js").glob("*.test.mjs"))


def test_editor_modules_pass_node_test(tmp_path):
    from service.api.routes.health import current_domain

    node = shutil.which("node")
    assert node, "node is needed for the editor's unit tests (docs/testing.md)"
    assert TESTS, "no tests/static/js/*.test.mjs"
    domain = tmp_path / "domain.json"
    domain.write_text(current_domain().model_dump_json())
    done = subprocess.run(
        [node, "--test", *map(str, TESTS)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "COATED_DOMAIN_JSON": str(domain)},
    )
    report = done.stdout + done.stderr
    assert done.returncode == 0, report[-4000:]
    passed = re.search(r"^# pass (\d+)", report, re.M)
    failed = re.search(r"^# fail (\d+)", report, re.M)
    assert passed and int(passed.group(1)) >= 15 and failed and failed.group(1) == "0", report[-4000:]
