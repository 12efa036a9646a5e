"""
No module outside the two registries treats a model kind by its name:
the kinds live in ``fitting/models/kinds.py`` (:class:`ModelKind`)
and ``fitting/fits/kinds.py`` (:class:`FitKind`), and every other module asks
them. Read from the source with ``ast``: a comparison with a kind's name
(``model == "rgb-conductor"``, ``kind in ("coated-conductor", ...)``) or a
table keyed by kind names (``{"coated-conductor": ...}``) anywhere else in
the Python packages fails.

The browser and the GLSL are read too: a kind's name as a string literal
in ``static/**/*.js`` / ``*.html`` or in a package under ``web/*/src`` (the
browser's kinds come from ``GET /api/v1/domain``, static/kinds.js), and a
preprocessor switch on a kind (``#if CF_RGB_CONDUCTOR``: a macro named after
a kind, include guards aside) in the GLSL of ``preview_shaders/glsl/``,
``static/`` and the JavaScript that carries GLSL. The three.js package
(web/three/), which fetches nothing, reads its kinds from its
generated/kinds.js and kinds.d.ts: written from the registry by
``python -m preview_shaders.three_package`` (:data:`GENERATED_KINDS`, the
registry's copy; tests/preview_shaders/test_three_package_files.py fails when
they differ from what the registry gives), every other file of it counts
zero like the editor's.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

from fitting.models.kinds import MODEL_KINDS

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("fitting", "service", "preview_shaders", "benchmarks", "scripts")
REGISTRIES = {Path("fitting/models/kinds.py"), Path("fitting/fits/kinds.py")}
NAMES = frozenset(MODEL_KINDS)
BUILT_IN = ("coated-conductor", "rgb-conductor")
"""The kinds registered by fitting/models/kinds.py (a toy plugin's kind is not loaded here)."""
GENERATED_KINDS = frozenset({"web/three/src/generated/kinds.js", "web/three/src/generated/kinds.d.ts"})
"""The three.js package's copy of the registry, generated from it (the only browser files naming kinds)."""
BABYLON_USES = {"web/babylon/src/check_model.js": 3}
"""The Babylon.js package's remaining kind names (its copy of the three.js package's former checks of
the extension object; its kinds are not yet read from a generated registry): may lose uses, never gain one."""


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
            names = [
                n for sub in ast.walk(node.pattern) if isinstance(sub, ast.MatchValue) for n in _names_in(sub.value)
            ]
        else:
            continue
        if names:
            where = node.pattern if isinstance(node, ast.match_case) else node
            found.append(f"{where.lineno}: {ast.get_source_segment(source, where) or names}")
    return found


def test_the_check_sees_what_it_must_refuse():
    """The reader finds each form (the test can fail)."""
    name = next(iter(NAMES))
    for text in (
        f"x = model == {name!r}",
        f"x = {name!r} != model",
        f"x = kind in ({name!r}, 'y')",
        f"T = {{{name!r}: 1}}",
        f"match m:\n    case {name!r}:\n        pass",
    ):
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


def _macro(name: str) -> str:
    return "CF_" + re.sub(r"\W", "_", name).upper()


def js_kind_uses(source: str) -> list[str]:
    """Each string literal that is a kind's name, and each preprocessor switch on a kind, as ``line: text``."""
    names = "|".join(map(re.escape, sorted(NAMES)))
    macros = "|".join(_macro(name) for name in sorted(NAMES))
    patterns = [
        re.compile(r"""["'`](%s)["'`]""" % names),
        re.compile(r"^[ \t]*#[ \t]*(?:if|ifdef|ifndef|elif|define)\b.*\b(%s)\b" % macros, re.M),
    ]
    found = [(m.start(), m.group(0).strip()) for pattern in patterns for m in pattern.finditer(source)]
    return [f"{source.count(chr(10), 0, at) + 1}: {text}" for at, text in sorted(found)]


def test_the_browser_check_sees_what_it_must_refuse():
    assert set(BUILT_IN) <= NAMES
    for text in (
        'if (model.kind === "rgb-conductor") x();',
        "const KINDS = ['coated-conductor'];",
        "#if CF_RGB_CONDUCTOR\n",
        "  #define CF_COATED_CONDUCTOR 1",
        "#ifdef CF_RGB_CONDUCTOR",
    ):
        assert js_kind_uses(text), text
    for text in ("#ifndef CF_RGB_CONDUCTOR_GLSL", "// the coated-conductor model", "kind.name === defaultModelKind()"):
        assert not js_kind_uses(text), text


def _browser_files():
    yield from (p for p in sorted((ROOT / "static").rglob("*")) if p.suffix in (".js", ".html", ".frag", ".glsl"))
    yield from (
        p for p in sorted((ROOT / "preview_shaders" / "glsl").iterdir()) if p.suffix in (".frag", ".vert", ".glsl")
    )
    for package in sorted((ROOT / "web").iterdir()):
        if (package / "src").is_dir():
            yield from (p for p in sorted((package / "src").rglob("*")) if p.suffix in (".js", ".mjs", ".ts"))


def test_no_browser_or_glsl_file_names_a_kind():
    wrong = []
    for path in _browser_files():
        relative = path.relative_to(ROOT)
        if "node_modules" in relative.parts or relative.as_posix() in GENERATED_KINDS:
            continue
        uses = js_kind_uses(path.read_text(encoding="utf-8"))
        allowed = BABYLON_USES.get(relative.as_posix(), 0)
        if len(uses) > allowed:
            wrong += [f"{relative}:{use}" for use in uses]
        elif len(uses) < allowed:
            wrong.append(f"{relative}: {len(uses)} kind names where {allowed} are allowed: lower BABYLON_USES")
    assert not wrong, "\n".join(wrong)


def test_the_package_s_generated_kinds_are_the_registry_s():
    """The files let through are the generator's output, and they name every registered kind."""
    from preview_shaders import three_package

    assert {f"web/three/src/generated/{name}" for name in three_package.KIND_FILES} == GENERATED_KINDS
    generated = (ROOT / "web/three/src/generated/kinds.js").read_text(encoding="utf-8")
    assert generated == three_package.kinds_module()
    assert {use.split(": ", 1)[1].strip("\"'`") for use in js_kind_uses(generated)} == set(BUILT_IN)
