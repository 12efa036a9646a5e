"""
Two checkouts timed side by side
================================

What the benchmarks that compare this checkout with an earlier commit share
(``fit_time_guard.py``, ``export_speed.py``):

-   :func:`checkout`: a git worktree of a commit, for the benchmark's run;
-   :class:`Side`: a child process of the benchmark's own script
    (``--child ROOT ...``), which imports the code of ``ROOT`` and answers
    one JSON line per item it is sent, so that the two sides take turns item
    by item and the machine's drifting load and CPU steal land on both alike
    (whole runs in turn moved one round's ratio by up to 0.25 on the
    developers' machine);
-   :func:`serve`: the child's side of that exchange.
"""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


INSTALLED = ("scripts/three/node_modules",)
"""What ``scripts/bootstrap`` installs in the tree (git-ignored) that the core reads: linked into a worktree."""

SUITE_INSTALLED = (
    ".venv",
    ".venv-blender",
    "scripts/gltf-validator/node_modules",
    "scripts/swagger-ui/node_modules",
    *INSTALLED,
)
"""What ``scripts/bootstrap`` installs in the tree (git-ignored) that the test suite reads."""


@contextlib.contextmanager
def checkout(rev: str, installed: tuple[str, ...] = INSTALLED) -> Iterator[Path]:
    """A detached git worktree of ``rev`` in a temporary directory (``installed`` linked), removed after."""
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp) / "before"
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(root), rev], check=True, capture_output=True
        )
        for path in installed:
            if (ROOT / path).exists() and not (root / path).exists():
                (root / path).symlink_to(ROOT / path, target_is_directory=True)
        try:
            yield root
        finally:
            subprocess.run(
                ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(root)], check=False, capture_output=True
            )


class Side:
    """``python SCRIPT --child ROOT ARGS...``: the items it offers (:attr:`names`) and its answer to each (:meth:`ask`)."""

    def __init__(self, script: str | Path, root: str | Path, *args: str) -> None:
        self.root = str(root)
        self.process = subprocess.Popen(
            [sys.executable, str(script), "--child", self.root, *args],
            cwd=tempfile.gettempdir(),
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        self.names = self._answer()

    def ask(self, name: str):
        self.process.stdin.write(name + "\n")
        self.process.stdin.flush()
        return self._answer()

    def _answer(self):
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError(f"the side of {self.root} exited ({self.process.wait()}); its stderr is above")
        return json.loads(line)

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait(timeout=60)


def serve(names: Iterable[str], answer: Callable[[str], object]) -> int:
    """The child: print ``names`` (one JSON line), then answer each item read from stdin with ``answer(item)``."""
    print(json.dumps(list(names)), flush=True)
    for line in sys.stdin:
        print(json.dumps(answer(line.strip())), flush=True)
    return 0
