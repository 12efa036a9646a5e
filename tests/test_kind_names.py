"""
No module outside the two registries treats a model kind by its name:
the kinds live in ``fitting/models/kinds.py`` (:class:`ModelKind`)
and ``fitting/fits/kinds.py`` (:class:`FitKind`), and every other module asks
them. Read from the source with ``ast``: a comparison with a kind's name
(``model == "rgb-conductor"``, ``kind in ("coated-conductor", ...)``) or a
table keyed by kind names (``{"coated-conductor": ...}``) anywhere else in
the Python packages fails.
"""

from __future__ import annotations

import ast
from pathlib import Path

from fitting.models.kinds import MODEL_KINDS

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("fitting", "service", "preview_shaders", "benchmarks", "scripts")
REGISTRIES = {Path("fitting/models/kinds.py"), Path("fitting/fits/kinds.py")}
NAMES = frozenset(MODEL_KINDS)


def _names_in(node: ast.AST) -> list[str]:
    """The kind names a literal operand holds (a string, or a tuple / list / set of strings)."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value] if node.value in NAMES else []
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return [name for element in node.elts for name in _names_in(element)]
    return []


def kind_name_uses(source: str, file_name: str = "<source>") -> list[str]:
    """Each comparison with a kind name and each table keyed by kind names, as ``line: text``."""
    found = []
    for node in ast.walk(ast.parse(source, file_name)):
        if isinstance(node, ast.Compare):
            names = [n for operand in [node.left, *node.comparators] for n in _names_in(operand)]
        elif isinstance(node, ast.Dict):
            names = [n for key in node.keys if key is not None for n in _names_in(key)]
        elif isinstance(node, ast.match_case):
            names = [n for sub in ast.walk(node.pattern) if isinstance(sub, ast.MatchValue)
                     for n in _names_in(sub.value)]
        else:
            continue
        if names:
            where = node.pattern if isinstance(node, ast.match_case) else node
            found.append(f"{where.lineno}: {ast.get_source_segment(source, where) or names}")
    return found


def test_the_check_sees_what_it_must_refuse():
    """The reader finds each form (the test can fail)."""
    name = next(iter(NAMES))
    for text in (f"x = model == {name!r}", f"x = {name!r} != model", f"x = kind in ({name!r}, 'y')",
                 f"T = {{{name!r}: 1}}", f"match m:\n    case {name!r}:\n        pass"):
        assert kind_name_uses(text), text
    assert not kind_name_uses(f"CANDIDATES = (({name!r}, 0),)\nx = model == DEFAULT_MODEL")


def test_no_module_outside_the_registries_compares_kind_names():
    wrong = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            relative = path.relative_to(ROOT)
            if relative in REGISTRIES or "node_modules" in relative.parts:
                continue
            wrong += [f"{relative}:{use}" for use in kind_name_uses(path.read_text(encoding="utf-8"), str(path))]
    assert not wrong, "\n".join(wrong)
