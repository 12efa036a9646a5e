"""
The house rules of ``docs/architecture.md``, read from the source with ``ast``:
module sizes in every Python package, the layers of ``fitting/``, who may
import whom, and no import cycles.
"""

from __future__ import annotations

import ast
import functools
import os
from collections import UserDict
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("fitting", "service", "preview_shaders", "benchmarks")
"""Every Python package of the house (``scripts/`` holds no Python; ``tests/`` are not a package)."""
MAX_MODULE_LINES = 400
MAX_ROUTE_LINES = 160

# Layer of each part of fitting/: a module may import its own layer and the
# layers below, never a higher one.
LAYERS = {
    "fitting.domain": 0,
    "fitting.numerics": 0,
    "fitting.optics": 1,
    "fitting.colour": 2,
    "fitting.models": 3,
    "fitting.fits": 4,
    "fitting.shading": 4,
    "fitting.exports": 5,
    "fitting.batch": 5,
    "fitting.cli": 6,
    "fitting": 7,  # fitting/__init__.py and __main__.py: the public face
}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules(package: str) -> dict[str, Path]:
    return {_module_name(p): p for p in sorted((ROOT / package).rglob("*.py"))}


ALL = {name: path for package in PACKAGES for name, path in _modules(package).items()}


def _imports(name: str, path: Path) -> set[str]:
    """Modules of the packages that ``name`` imports (absolute names)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            # "from .x import y": y may itself be a module.
            targets = [module] + [f"{module}.{alias.name}" for alias in node.names]
        else:
            continue
        for target in targets:
            while target and target not in ALL:
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


class _Graph(UserDict):
    """Module -> the modules of the packages it imports; read on first use, not when each worker collects."""

    def __init__(self) -> None:  # the data is read by the property below
        pass

    @functools.cached_property
    def data(self) -> dict[str, set[str]]:  # type: ignore[override]
        return {name: _imports(name, path) for name, path in ALL.items()}


GRAPH = _Graph()


def _layer(name: str) -> int:
    best = None
    for prefix, layer in LAYERS.items():
        if name == prefix or name.startswith(prefix + "."):
            if best is None or len(prefix) > len(best):
                best = prefix
    assert best is not None, f"{name} belongs to no layer of docs/architecture.md"
    return LAYERS[best]


def test_the_graph_is_read():
    """The reader sees the imports it must judge (the test can fail)."""
    assert "fitting.domain" in GRAPH["fitting.fits.solver"]
    assert "fitting.optics.nk" in GRAPH["fitting.optics.library"] or any(
        m.startswith("fitting.optics") for m in GRAPH["fitting.optics.library"]
    )
    assert GRAPH["fitting.domain"] == set()


FITTING = sorted(n for n in ALL if n.startswith("fitting"))
SERVICE = sorted(n for n in ALL if n.startswith("service"))


def _lines(name: str) -> int:
    return len(ALL[name].read_text(encoding="utf-8").splitlines())


def test_module_size():
    """No module of any package over 400 lines."""
    wrong = [f"{ALL[n].relative_to(ROOT)} has {_lines(n)} lines" for n in sorted(ALL) if _lines(n) > MAX_MODULE_LINES]
    assert len(ALL) > 100 and not wrong, "\n".join(wrong)


def test_every_package_is_read():
    """Each package of PACKAGES has modules in the graph, and no Python outside them goes unread."""
    assert all(any(n == p or n.startswith(p + ".") for n in ALL) for p in PACKAGES)
    outside = [path.relative_to(ROOT) for path in _python_files_outside((*PACKAGES, "tests", "static"))]
    assert not outside, outside


def _python_files_outside(folders: tuple[str, ...]) -> list[Path]:
    """
    The ``.py`` files under the repository's top-level folders but ``folders``,
    outside hidden folders and ``node_modules`` (not walked: on a fresh clone
    ``.venv`` and the npm folders are most of the tree).
    """
    found = []
    for top in sorted(ROOT.iterdir()):
        if not top.is_dir() or top.name in folders or top.name.startswith(".") or top.name == "node_modules":
            continue
        for folder, dirs, files in os.walk(top):
            dirs[:] = [d for d in dirs if not d.startswith(".") and d != "node_modules"]
            found += [Path(folder, name) for name in files if name.endswith(".py") and not name.startswith(".")]
    return found


def test_only_the_tools_import_the_benchmarks():
    """fitting/, service/ and preview_shaders/ never import benchmarks/; fitting/ never preview_shaders/."""
    wrong = [
        f"{n} imports {t}"
        for n, ts in GRAPH.items()
        for t in ts
        if (t.startswith("benchmarks") and not n.startswith("benchmarks"))
        or (n.startswith("fitting") and t.startswith("preview_shaders"))
    ]
    assert not wrong, "\n".join(wrong)


def test_no_fitting_layer_imports_a_higher_one():
    wrong = [
        f"{name} (layer {_layer(name)}) imports {target} (layer {_layer(target)})"
        for name, targets in GRAPH.items()
        if name.startswith("fitting")
        for target in sorted(targets)
        if target.startswith("fitting") and _layer(target) > _layer(name)
    ]
    assert not wrong, "\n".join(wrong)


def test_fitting_never_imports_the_service():
    wrong = [
        f"{n} imports {t}" for n, ts in GRAPH.items() if n.startswith("fitting") for t in ts if t.startswith("service")
    ]
    assert not wrong, "\n".join(wrong)


def _cycles() -> list[list[str]]:
    """Every strongly connected component of more than one module (Tarjan)."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(GRAPH[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(GRAPH):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles():
    # A package's __init__ importing its own modules is not a cycle of jobs.
    cycles = [c for c in _cycles() if not all(m == c[0] or m.startswith(c[0] + ".") for m in c)]
    assert not cycles, cycles


ROUTES = sorted(n for n in ALL if n.startswith("service.api.routes.") and n != "service.api.routes")


# The service's rules.
def test_service_module_size():
    """No module of service/ over 400 lines."""
    wrong = [f"{ALL[n].relative_to(ROOT)}: {_lines(n)}" for n in SERVICE if _lines(n) > MAX_MODULE_LINES]
    assert not wrong, wrong


def test_service_route_module_size():
    """No route module (service/api/routes/*) over 160 lines."""
    wrong = [f"{ALL[n].relative_to(ROOT)}: {_lines(n)}" for n in ROUTES if _lines(n) > MAX_ROUTE_LINES]
    assert ROUTES and not wrong, wrong


def test_service_no_route_imports_another_route():
    """Routes share code through service modules, never through another route."""
    wrong = [f"{n} imports {sorted(GRAPH[n] & set(ROUTES))}" for n in ROUTES if GRAPH[n] & set(ROUTES)]
    assert ROUTES and not wrong, wrong


def test_the_runtime_is_used_through_its_public_surface():
    """Outside service/runtime/, the service imports the runtime's package (its __init__'s names), never its modules."""
    wrong = [
        f"{n} imports {t}"
        for n, ts in GRAPH.items()
        if n.startswith("service") and not n.startswith("service.runtime")
        for t in ts
        if t.startswith("service.runtime.")
    ]
    assert "service.runtime" in GRAPH["service.main"]
    assert not wrong, "\n".join(wrong)


SERVICE_TOP_LEVEL_MAX = 12


def test_service_top_level_is_small():
    """service/ holds at most 12 entries (the runtime, the API, the jobs, the store...: each one room)."""
    entries = sorted(p.name for p in (ROOT / "service").iterdir() if p.name != "__pycache__")
    assert len(entries) <= SERVICE_TOP_LEVEL_MAX, entries
