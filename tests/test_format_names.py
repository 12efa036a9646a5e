"""
No module outside the registry of export formats
(``fitting/exports/formats.py``; the exports package itself keys its
tools' values by the same names) treats a format by its name: every list of
formats (the CLI's choices, the REST API's, ``GET /api/v1/domain``, the
editor's menu) is derived from it. Read from the Python source with
``ast`` (a comparison with a format's name, or a table keyed by format
names) and from the browser's JavaScript and HTML (a format's name as a
string literal or an option's value).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

from fitting.exports.formats import EXPORT_FORMATS

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("fitting", "service", "preview_shaders")
"""The product's packages (benchmarks/ measure named tools on purpose)."""
EXPORTS = Path("fitting/exports")
"""The package of the registry and the writers; its tools (tool_layering) share the formats' names."""
NAMES = frozenset(EXPORT_FORMATS)


def _names_in(node: ast.AST) -> list[str]:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value] if node.value in NAMES else []
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return [name for element in node.elts for name in _names_in(element)]
    return []


def format_name_uses(source: str, file_name: str = "<source>") -> list[str]:
    """Each comparison with a format name and each table keyed by format names, as ``line: text``."""
    found = []
    for node in ast.walk(ast.parse(source, file_name)):
        if isinstance(node, ast.Compare):
            names = [n for operand in [node.left, *node.comparators] for n in _names_in(operand)]
        elif isinstance(node, ast.Dict):
            names = [n for key in node.keys if key is not None for n in _names_in(key)]
        elif isinstance(node, ast.Call) and any(k.arg == "choices" for k in node.keywords):
            names = [n for k in node.keywords if k.arg == "choices" for n in _names_in(k.value)]
        else:
            continue
        if names:
            found.append(f"{node.lineno}: {ast.get_source_segment(source, node) or names}")
    return found


def js_format_literals(source: str) -> list[str]:
    """Each string literal or option value of the browser's code that is a format's name."""
    pattern = re.compile(r"""["'`](%s)["'`]""" % "|".join(map(re.escape, sorted(EXPORT_FORMATS))))
    return [f"{source.count(chr(10), 0, m.start()) + 1}: {m.group(0)}" for m in pattern.finditer(source)]


def test_the_checks_see_what_they_must_refuse():
    for text in (
        'x = format == "openpbr"',
        'x = f in ("mtlx", "openpbr")',
        'T = {"openpbr": 1}',
        'p.add_argument("--export", choices=("openpbr", "x"))',
    ):
        assert format_name_uses(text), text
    assert not format_name_uses("x = format in EXPORT_FORMATS")
    assert js_format_literals('export const EXPORTS = new Set(["mtlx", "gltf"]);')
    assert js_format_literals('<option value="openpbr">')


def test_no_python_module_outside_the_registry_names_formats():
    wrong = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            relative = path.relative_to(ROOT)
            if EXPORTS not in relative.parents:
                wrong += [f"{relative}:{use}" for use in format_name_uses(path.read_text(encoding="utf-8"), str(path))]
    assert not wrong, "\n".join(wrong)


def test_the_browser_names_no_format():
    wrong = []
    for path in sorted((ROOT / "static").rglob("*")):
        if path.suffix in (".js", ".html") and "node_modules" not in path.parts:
            wrong += [f"{path.relative_to(ROOT)}:{use}" for use in js_format_literals(path.read_text(encoding="utf-8"))]
    assert not wrong, "\n".join(wrong)
