"""
The private parts of CPython's multiprocessing and of uvicorn that the
runtime uses, each behind its one adapter (service/runtime/mp_private.py,
service/runtime/server.py), are still what those adapters expect: a Python
or uvicorn release that changes them fails here, by name, not as a pool
that hangs or a connection bound that no longer holds.
"""

from __future__ import annotations

import ast
from pathlib import Path

from service.runtime import mp_private, server

ROOT = Path(__file__).resolve().parents[2]
RUNTIME = ROOT / "service" / "runtime"


def test_multiprocessing_holds_what_the_adapter_uses():
    assert mp_private.mismatches() == []


def test_uvicorn_holds_what_the_adapter_uses():
    assert server.uvicorn_mismatches() == []


def test_the_checks_can_fail():
    """A name the classes do not have is reported (the checks read the real classes)."""
    from uvicorn.protocols.http.h11_impl import H11Protocol

    saved = dict(server.UVICORN_PRIVATE)
    try:
        server.UVICORN_PRIVATE[H11Protocol] = ("conn", "_no_such_state")
        assert server.uvicorn_mismatches() == [
            f"uvicorn's H11Protocol has no _no_such_state (uvicorn {server.uvicorn.__version__})"
        ]
    finally:
        server.UVICORN_PRIVATE.clear()
        server.UVICORN_PRIVATE.update(saved)


def _private_reads(path: Path, names: set[str]) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [
        f"{path.name}:{node.lineno} .{node.attr}"
        for node in ast.walk(tree)
        if isinstance(node, ast.Attribute) and node.attr in names
    ]


def _imports_uvicorn(path: Path) -> bool:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names]
    names += [node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
    return any(name.split(".")[0] in ("uvicorn", "h11") for name in names)


def test_only_the_adapters_touch_the_private_state():
    """No other module of the service names multiprocessing's private attributes or imports uvicorn (or h11)."""
    mp_names = {name for name in mp_private.FORK_SERVER_STATE if name.startswith("_forkserver")} | {
        "_forkserver",
        "_result_queue",
        "_writer",
    }
    wrong = []
    for path in sorted((ROOT / "service").rglob("*.py")):
        if path != RUNTIME / "mp_private.py":
            wrong += _private_reads(path, mp_names)
        if path != RUNTIME / "server.py" and _imports_uvicorn(path):
            wrong.append(f"{path.relative_to(ROOT)} imports uvicorn")
    assert not wrong, wrong
