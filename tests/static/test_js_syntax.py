"""
Every browser module the service serves parses as an ES module: the editor
(``static/``) and the three.js package (``web/three/src``). A syntax error
in one module stops the whole page from loading, and the node unit tests
only import the modules they test, so this reads every one of them, in one
node process (``vm.SourceTextModule`` parses without running).
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FOLDERS = (ROOT / "static", ROOT / "web" / "three" / "src")

pytestmark = pytest.mark.slow

PARSE = """
const vm = require("node:vm");
const fs = require("node:fs");
const bad = [];
for (const path of JSON.parse(process.argv[1])) {
  try { new vm.SourceTextModule(fs.readFileSync(path, "utf8"), { identifier: path }); }
  catch (error) { bad.push(`${path}: ${error.message}`); }
}
console.log(JSON.stringify(bad));
"""


def modules() -> list[str]:
    return sorted(str(p) for folder in FOLDERS for p in folder.rglob("*.js") if "node_modules" not in p.parts)


def parse_errors(paths: list[str]) -> list[str]:
    out = subprocess.run(
        [shutil.which("node"), "--experimental-vm-modules", "--no-warnings", "-e", PARSE, json.dumps(paths)],
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    return json.loads(out.stdout)


def test_every_served_module_parses():
    paths = modules()
    assert len(paths) > 20, paths  # the editor's and the package's modules were found
    assert parse_errors(paths) == []


def test_the_check_sees_a_syntax_error(tmp_path):
    broken = tmp_path / "broken.js"
    broken.write_text("export const x = (1 + 2));\n", encoding="utf-8")
    fine = tmp_path / "fine.js"
    fine.write_text('import { y } from "./y.js";\nexport const x = y + 1;\n', encoding="utf-8")
    errors = parse_errors([str(broken), str(fine)])
    assert len(errors) == 1 and errors[0].startswith(str(broken))
