"""
The README's command-line examples, run as a newcomer copies them (in a
folder of their own, one after another: a later line reads what an earlier
one wrote), its REST examples with curl against a real server, and the
catalogue names its prose promises. A README example
that no longer works is the first thing a user meets.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, run_command, server_process

from fitting.optics.catalogue import resolve_material

README = (ROOT / "README.md").read_text()

LONG = {"reproduce": "a minute of fits (the 22 conductors, every baseline): checked to parse (--help)"}
"""Commands run with ``--help`` instead, and why."""


def command_lines() -> list[list[str]]:
    """The ``.venv/bin/python -m ...`` lines of the README's "On the command line" block, comments cut."""
    block = README.split("**On the command line**", 1)[1].split("```sh", 1)[1].split("```", 1)[0]
    lines = [line.split("#", 1)[0].strip() for line in block.strip().splitlines()]
    return [shlex.split(line) for line in lines if line]


def write_nk_csv(path: Path) -> None:
    """An n, k file as the README's ``my_metal.csv``: a smooth gold-like metal, 360-830 nm every 10 nm."""
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


@pytest.mark.slow  # processes and a GL context: about 15 s
def test_the_command_line_examples_run_in_order(tmp_path):
    write_nk_csv(tmp_path / "my_metal.csv")
    lines = command_lines()
    assert len(lines) >= 6
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for argv in lines:
        assert argv[:2] == [".venv/bin/python", "-m"], argv
        module, args = argv[2], argv[3:]
        if args and args[0] in LONG:
            args = [args[0], "--help"]
        result = run_command(module, *args, cwd=tmp_path, env=env)
        assert result.returncode == 0, (argv, result.stderr[-2000:])
    for written in re.findall(r"-o (\S+)", README.split("**On the command line**", 1)[1].split("```", 2)[1]):
        assert (tmp_path / written).stat().st_size > 0, written


def rest_commands() -> list[str]:
    """The README's ``curl`` lines of the "Over REST" block, continuation lines joined, comments cut."""
    block = README.split("**Over REST**", 1)[1].split("```sh", 1)[1].split("```", 1)[0]
    joined = block.replace("\\\n", " ")
    return [line.strip() for line in joined.splitlines() if line.strip() and not line.strip().startswith("#")]


@pytest.mark.slow  # a server process and curl
def test_the_rest_examples_answer_with_curl(tmp_path):
    """
    Each ``curl`` line as the README writes it, against a real server
    (``localhost:8000`` its address, ``ID`` the id the first example
    answered, the file to import one the service exported under that
    name), answered 2xx; the downloads are written where curl runs.
    """
    commands = rest_commands()
    assert len(commands) >= 8 and all(c.startswith("curl ") for c in commands), commands
    write_nk_csv(tmp_path / "my-metal.csv")
    fit_id = None
    with server_process(tmp_path / "data") as server:
        address = server.url.removeprefix("http://")
        for command in commands:
            if fit_id is not None:
                command = command.replace("/ID/", f"/{fit_id}/")
            for name in re.findall(r"file=@(\S+\.gltf)", command):  # a user's export of the first fit
                gltf = f"{server.url}/api/v1/fits/{fit_id}/pack?format=gltf&eta_i=1.33"
                subprocess.run(["curl", "-s", "-o", name, gltf], cwd=tmp_path, check=True, timeout=120)
            done = subprocess.run(
                command.replace("localhost:8000", address) + " -w '\\n%{http_code}'",
                shell=True,
                cwd=tmp_path,
                capture_output=True,
                text=True,
                timeout=300,
            )
            body, _, status = done.stdout.rpartition("\n")
            assert done.returncode == 0 and status.startswith("2"), (command, status, body[-500:], done.stderr)
            if fit_id is None:
                fit_id = json.loads(body)["id"]
    downloads = {p.name for p in tmp_path.iterdir()}
    assert any(n.endswith(".cfpk") for n in downloads) and any(n.endswith("acescg.mtlx") for n in downloads)
