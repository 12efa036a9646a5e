"""
benchmarks/side_by_side.py, what the benchmarks that time this checkout
against an earlier commit share: a side answers each item it is sent, in
order, from the checkout it was given; a side that fails says so; a
checkout is a worktree of the commit with the installed three.js linked in,
removed after.
"""

from __future__ import annotations

import subprocess
import textwrap
from pathlib import Path

import pytest

from benchmarks.side_by_side import INSTALLED, ROOT, SUITE_INSTALLED, Side, checkout

pytestmark = pytest.mark.slow  # starts processes, makes a git worktree

CHILD = textwrap.dedent("""
    import sys
    sys.path.insert(0, {root!r})
    from benchmarks.side_by_side import serve

    if __name__ == "__main__":
        assert sys.argv[1] == "--child"
        if sys.argv[3:] == ["--fail"]:
            raise SystemExit("cannot start")
        serve(["a", "bb"], lambda item: {{"item": item, "root": sys.argv[2], "length": len(item)}})
""")


def test_a_side_answers_each_item_from_its_root(tmp_path):
    script = tmp_path / "child.py"
    script.write_text(CHILD.format(root=str(ROOT)))
    side = Side(script, "/somewhere")
    try:
        assert side.names == ["a", "bb"]
        assert side.ask("bb") == {"item": "bb", "root": "/somewhere", "length": 2}
        assert side.ask("a")["length"] == 1
    finally:
        side.close()
    assert side.process.returncode == 0


def test_a_side_that_fails_to_start_says_so(tmp_path):
    script = tmp_path / "child.py"
    script.write_text(CHILD.format(root=str(ROOT)))
    with pytest.raises(RuntimeError, match="exited"):
        Side(script, "/somewhere", "--fail")


def test_a_checkout_is_the_commit_with_the_installed_dependencies_and_goes_away():
    head = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True, check=True
    ).stdout.strip()
    with checkout(head) as root:
        assert (root / "fitting" / "__init__.py").exists()
        worktree_head = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
        assert worktree_head == head
        for path in INSTALLED:
            assert (root / path).resolve() == (ROOT / path).resolve()
    assert not Path(root).exists()
    listed = subprocess.run(["git", "-C", str(ROOT), "worktree", "list"], capture_output=True, text=True).stdout
    assert str(root) not in listed


def test_a_checkout_for_the_suite_links_what_the_suite_reads_and_removing_it_keeps_them(tmp_path):
    assert all((ROOT / path).is_dir() for path in SUITE_INSTALLED)  # scripts/test runs scripts/bootstrap first
    with checkout("HEAD", SUITE_INSTALLED) as root:
        for path in SUITE_INSTALLED:
            assert (root / path).is_symlink() and (root / path).resolve() == (ROOT / path).resolve()
    assert all((ROOT / path).is_dir() for path in SUITE_INSTALLED)
    assert all((ROOT / path).exists() for path in (".venv/bin/python", ".venv-blender/bin/python"))
