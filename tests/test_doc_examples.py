"""
The examples a user copies from the README and the guides, run as written:
each document's shell blocks line by line in a folder of its own (a later
line reads what an earlier one wrote), ``curl`` against a real server and
``.venv/bin/python -m ...`` as commands; and the catalogue names the
README's prose promises. An example that no longer works is the first
thing a user meets.

What the examples leave to the reader is filled in as a reader would:
``localhost:8000`` is the server's address; ``ID`` the first fit the
document's examples answered, ``ID1`` and ``ID2`` the first two (gold's
and copper's fits where the document has not made two); an n, k
file (``my-metal.csv``) is a smooth gold-like metal, ``scene.json`` the
README's scene; a file to import that
no example wrote is the first fit's export of that kind, downloaded under
the document's name. Lines that run the service, the tests or the
benchmarks are not examples of using it and are left out.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import loopback
import numpy as np
import pytest
from conftest import ROOT, run_command, server_process

from fitting.optics.catalogue import resolve_material

README = (ROOT / "README.md").read_text()
DOCUMENTS = ("README.md", "docs/service.md", "docs/exports.md", "docs/edge_tint.md", "docs/fitting.md")
"""The documents whose shell examples are run (docs/batch.md's and docs/speed-vs-error.md's fit whole
shelves of the database, or rebuild the committed catalogue: minutes each, and their own tests run them)."""

SCENE = {"materials": [{"material": "Au", "eta_i": 1.5}, {"material": "Cu", "eta_i": {"min": 1.3, "max": 1.6}}]}
"""The reader's ``scene.json``: the README's scene."""

NK_FILES = ("my_metal.csv", "my-metal.csv", "my-gold.csv")
"""The n, k files the examples name (the reader's own)."""

LONG = {"reproduce": "a minute of fits (the 22 conductors, every baseline): checked to parse (--help)"}
"""Commands run with ``--help`` instead, and why."""

EXPORTS = {".gltf": "gltf", ".glb": "glb", ".mtlx": "mtlx", ".py": "blender"}
"""A file to import that no example wrote: the export its extension names."""


def examples(document: str) -> list[list[str]]:
    """
    The curl and ``python -m fitting|preview_shaders`` commands of ``document``'s ``sh`` blocks, in
    order, each as its words (a shell's: lines joined where a backslash or an open quote continues
    them, comments cut).
    """
    text = (ROOT / document).read_text()
    commands, pending = [], ""
    for block in re.findall(r"```sh\n(.*?)```", text, flags=re.S):
        for line in block.replace("\\\n", " ").splitlines():
            pending = f"{pending}\n{line}" if pending else line
            try:
                words = shlex.split(pending, comments=True)
            except ValueError:  # a quote still open: the command goes on
                continue
            pending = ""
            if words[:1] == ["curl"] or words[:3] in (
                [".venv/bin/python", "-m", "fitting"],
                [".venv/bin/python", "-m", "preview_shaders"],
            ):
                commands.append(words)
    return commands


def write_nk_csv(path: Path) -> None:
    """An n, k file: a smooth gold-like metal, 360-830 nm every 10 nm."""
    wavelength = np.arange(360.0, 831.0, 10.0)
    n = 0.2 + 1.3 * np.exp(-(((wavelength - 360.0) / 150.0) ** 2))
    k = 1.8 + 4.0 * (wavelength - 360.0) / 470.0
    rows = "\n".join(f"{w:g},{a:.4f},{b:.4f}" for w, a, b in zip(wavelength, n, k))
    path.write_text("wavelength_nm,n,k\n" + rows + "\n")


def test_the_prose_s_names_resolve():
    """The catalogue names the README says `scripts/serve` knows each name a page."""
    names = re.search(r"by its common\s+name: ([^)]*)\)", README).group(1)
    for name in [n.strip() for n in names.split(",")]:
        assert resolve_material(name), name


def test_each_document_has_examples():
    counts = {document: len(examples(document)) for document in DOCUMENTS}
    assert all(count >= 1 for count in counts.values()) and counts["README.md"] >= 14, counts


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with server_process(tmp_path_factory.mktemp("examples") / "data") as running:
        yield running


@pytest.mark.slow  # a server, commands and a GL context
@pytest.mark.parametrize("document", DOCUMENTS)
def test_the_examples_run_as_written(document, server, tmp_path):
    for name in NK_FILES:
        write_nk_csv(tmp_path / name)
    (tmp_path / "scene.json").write_text(json.dumps(SCENE))
    address = server.url.removeprefix("http://")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    fits: list[str] = []
    for words in examples(document):
        line = shlex.join(words)
        if re.search(r"\bID[12]?\b", line) and len(fits) < 2:  # a document that starts from "any stored fit"
            for body in ({"material": "Au"}, {"material": "Cu"})[len(fits) :]:
                fits.append(loopback.post(f"{server.url}/api/v1/fits", json=body, timeout=300).json()["id"])
        words = [_filled(word, fits, address) for word in words]
        if words[0] == "curl":
            for name in [w.split("@", 1)[1] for w in words if w.startswith("file=@")]:
                if not (tmp_path / name).exists():
                    kind = EXPORTS[Path(name).suffix]
                    url = f"{server.url}/api/v1/fits/{fits[0]}/pack?format={kind}&eta_i=1.33"
                    subprocess.run(["curl", "-sf", "-o", name, url], cwd=tmp_path, check=True, timeout=300)
            done = subprocess.run(
                [*words, "-w", "\n%{http_code}"], cwd=tmp_path, capture_output=True, text=True, timeout=300
            )
            body, _, status = done.stdout.rpartition("\n")
            assert done.returncode == 0 and status.startswith("2"), (document, line, status, body[-500:])
            if any(w.endswith("/api/v1/fits") for w in words) and body.startswith("{"):
                fit = json.loads(body).get("id")
                if fit and fit not in fits:
                    fits.append(fit)
        else:
            module, args = words[2], words[3:]
            if args and args[0] in LONG:
                args = [args[0], "--help"]
            result = run_command(module, *args, cwd=tmp_path, env=env)
            assert result.returncode == 0, (document, line, result.stderr[-2000:])
            for written in [args[i + 1] for i, w in enumerate(args[:-1]) if w == "-o"]:
                assert (tmp_path / written).stat().st_size > 0, (document, line)


def _filled(word: str, fits: list[str], address: str) -> str:
    """``word`` with the reader's values: the server's address, the fits' ids for ``ID1``, ``ID2``, ``ID``."""
    word = word.replace("localhost:8000", address)
    for i, fit in enumerate(fits[:2]):
        word = word.replace(f"ID{i + 1}", fit)
    return re.sub(r"\bID\b", fits[0], word) if fits else word


READER = {"usda_document": 'def usda_document(values):\n    return "#usda 1.0\\n"\n'}
"""What a Python example leaves to the reader to write, as the reader would write it."""


def python_examples() -> list[tuple[str, str]]:
    """(document, code) of every ``python`` block of the README and docs/ (at the margin: a block indented
    in a list is a step of a recipe, such as docs/architecture.md's new model kind, not a program)."""
    return [
        (path.relative_to(ROOT).as_posix(), code)
        for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
        for code in re.findall(r"^```python\n(.*?)^```", path.read_text(), flags=re.S | re.M)
    ]


@pytest.mark.slow  # a Python process each
def test_the_python_examples_run(tmp_path):
    examples = python_examples()
    assert len(examples) >= 3
    for document, code in examples:
        prelude = "".join(text for name, text in READER.items() if re.search(rf"\b{name}\b", code))
        done = subprocess.run(
            [sys.executable, "-c", prelude + code],
            cwd=tmp_path,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 0, (document, code, done.stderr[-2000:])
