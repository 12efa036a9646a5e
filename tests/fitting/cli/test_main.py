"""
The `python -m fitting` command line, run as a user would: the command
itself once, then forked from the suite's program that has imported it
(tests/conftest.py's ``run_command``: the same ``python -m`` without its
imports).
"""

import json
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import run_command

from fitting.models.pack import decode_pack

ROOT = Path(__file__).resolve().parents[3]


def run(*args, check=True):
    result = run_command("fitting", *args)
    if check:
        assert result.returncode == 0, result.stderr
    return result


@pytest.mark.slow  # starts a process or GL context
def test_library_lists_the_catalogue():
    # The command itself, as a user types it (the other tests fork it).
    result = subprocess.run(
        [sys.executable, "-m", "fitting", "library"], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 0, result.stderr
    lines = result.stdout.strip().splitlines()
    assert len(lines) >= 300
    (gold,) = [line for line in lines if line.startswith("Au ")]
    assert " gold " in gold and "Johnson" in gold


@pytest.mark.slow  # 2.6 s (all cases 2.6 s) in a --durations=0 run
def test_fit_writes_binary_pack(tmp_path):
    out = tmp_path / "au.cfpk"
    run("fit", "gold", "--eta-range", "1:2", "--no-metrics", "-o", str(out))
    (material,) = decode_pack(out.read_bytes())
    assert material.name == "Au" and material.eta_i_range == (1.0, 2.0)


@pytest.mark.slow  # 2.6 s (all cases 2.6 s) in a --durations=0 run
def test_fit_json_with_metrics():
    view = json.loads(run("fit", "Cu", "--json").stdout)
    assert view["colour_space"] == "ACEScg" and view["fit"]["success"]
    # A product claim, not a precision bound: the fit's mean Delta E below
    # 0.2 (docs/fitting.md: mean float16 Delta E 0.147 on the 22 conductors).
    assert view["metrics"]["model_float16"]["delta_E_mean"] < 0.2


@pytest.mark.slow  # 2.6 s (all cases 2.6 s) in a --durations=0 run
def test_fit_user_file(tmp_path):
    path = tmp_path / "metal.csv"
    path.write_text(
        "wavelength_nm,n,k\n350,0.4,2.0\n450,0.5,2.5\n550,0.55,2.8\n650,0.6,3.0\n750,0.7,3.8\n850,0.8,4.5\n"
    )
    view = json.loads(run("fit", "--nk", str(path), "--no-metrics").stdout)
    assert view["name"] == "metal" and view["source"].startswith("user CSV")
    # Six samples 100 nm apart: the fit says how far its figure can be off.
    uncertainty = view["fit"]["quality"]["uncertainty"]
    assert uncertainty["samples_inside_visible"] == 4 and uncertainty["delta_E_mean"] > 0


@pytest.mark.slow  # starts processes
def test_sparse_file_refused_or_fitted_with_a_warning(tmp_path):
    # Three samples leave gaps of 250 nm inside 360-830 nm.
    path = tmp_path / "sparse.csv"
    path.write_text("wavelength_nm,n,k\n350,0.4,2.0\n600,0.6,3.0\n850,0.8,4.5\n")
    refused = run("fit", "--nk", str(path), "--no-metrics", check=False)
    assert refused.returncode == 2 and "between 360 and 600 nm" in refused.stderr
    relaxed = run("fit", "--nk", str(path), "--no-metrics", "--max-gap-nm", "300")
    assert "warning: sparse data" in relaxed.stderr
    assert "warning: sparse data" in json.loads(relaxed.stdout)["source"]


@pytest.mark.slow  # starts processes
def test_strict_refuses_a_model_outside_the_range(tmp_path):
    # Constant n = 1.5 glass: the coated-conductor model leaves [0, 1] on it.
    path = tmp_path / "glass.csv"
    rows = "\n".join(f"{w},1.5,0" for w in range(300, 901, 10))
    path.write_text("wavelength_nm,n,k\n" + rows + "\n")
    loose = run("fit", "--nk", str(path), "--no-metrics")
    assert "leaves [0, 1]" in loose.stderr
    strict = run("fit", "--nk", str(path), "--no-metrics", "--strict", "-o", str(tmp_path / "g.cfpk"), check=False)
    assert strict.returncode == 3 and "leaves [0, 1]" in strict.stderr
    assert not (tmp_path / "g.cfpk").exists()


@pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
def test_fit_any_database_page():
    view = json.loads(run("fit", "--page", "main/Ni/Johnson", "--no-metrics").stdout)
    assert view["name"] == "Ni (Johnson)" and "main/Ni/Johnson" in view["source"]


@pytest.mark.slow  # 4.2 s (all cases 4.2 s) in a --durations=0 run
def test_errors_are_clear():
    result = run("fit", "--page", "main/Ni", check=False)
    assert result.returncode == 2 and "SHELF/BOOK/PAGE" in result.stderr
    result = run("fit", "Unobtainium", check=False)
    assert result.returncode == 2 and "`material` must name a conductor of the library" in result.stderr
    result = run("fit", "Au", "--eta-range", "2:1", check=False)
    assert result.returncode == 2 and "`eta_i_range` must satisfy" in result.stderr
    result = run("fit", "Au", "--eta-range", "x", check=False)
    assert result.returncode == 2 and "--eta-range must be LO:HI" in result.stderr


@pytest.mark.slow  # 4.3 s (all cases 4.3 s) in a --durations=0 run
def test_reproduce_subset(tmp_path):
    out = tmp_path / "results.md"
    out.write_text(
        "old\n<!-- end of the part written by python -m fitting reproduce: what follows is kept by "
        "--write-docs -->\n\n## Kept\n"
    )
    result = run("reproduce", "--materials", "Au,Ta", "-o", str(out))
    assert "2/2" in result.stderr and f"wrote {out}" in result.stderr  # progress bar, where it went
    assert "| Au |" in result.stdout and "| Ta |" in result.stdout  # the table, printed
    text = out.read_text()
    assert "| Au |" in text and "| Ta |" in text and "beats every baseline on every conductor: **yes**" in text
    assert "old" not in text and text.endswith("-->\n\n## Kept\n")  # the page written again, the rest kept
