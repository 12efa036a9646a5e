"""
What a command's start imports: ``python -m fitting fit`` of a coated-conductor
material never imports scipy.optimize, scipy.interpolate or colour-science
(most of a start: their import took about 1 s of a 30 ms fit); the commands that need them
import them when they run. Nor numpy.ma (about 15 ms), which numpy's unique and median import
(fitting.numerics.plain has theirs without it). Nor does it import the parts of the package other
commands need (the export writers, the batch, scenes): only the command's own
parser is built, and the export formats are read when ``--export`` is checked.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
HEAVY = ("scipy.optimize", "scipy.interpolate", "colour", "matplotlib", "numpy.ma")

OTHER_COMMANDS = ("fitting.exports", "fitting.batch", "fitting.fits.scene_fit", "fitting.shading")

_PROBE = """
import contextlib, io, json, sys
from fitting.cli.main import main
watched = json.loads(sys.argv[1])
with contextlib.redirect_stdout(io.StringIO()):
    status = main(sys.argv[2:])
print(json.dumps({"status": status, "loaded": [m for m in watched if m in sys.modules]}))
"""


def _loaded_after(*args: str, watched=HEAVY) -> dict:
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, json.dumps(watched), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.slow  # starts a process
def test_fit_imports_neither_scipy_optimize_nor_colour_science():
    """
    A fit of dense data (W, Weaver: no gap wide enough for the data-uncertainty
    splines, a guard that needs no SLSQP refit) imports neither, though the
    CLI's parser imports every export writer; nor does one of data with a wide
    gap (Au, Johnson: 65 nm), whose uncertainty reads the data with splines
    (fitting.numerics.splines, not scipy.interpolate, whose import alone was
    ~0.5 s). The conductors whose guard refits under a capped max (Al, K, Mo)
    load scipy.optimize for SLSQP.
    """
    for material in ("W", "Au"):
        after = _loaded_after("fit", material, "--json")
        assert after == {"status": 0, "loaded": []}, material


@pytest.mark.slow  # starts a process
def test_the_probe_sees_an_import():
    """The probe can fail: the rgb-conductor fit, which solves with scipy, shows scipy.optimize loaded."""
    after = _loaded_after("fit", "Au", "--json", "--model", "rgb-conductor")
    assert after["status"] == 0 and "scipy.optimize" in after["loaded"]


@pytest.mark.slow  # starts processes
def test_fit_imports_no_other_command_s_modules(tmp_path):
    """``fit Au`` builds its own parser only; ``fit Au --export gltf`` loads the exports (it writes one)."""
    assert _loaded_after("fit", "Au", "--json", watched=OTHER_COMMANDS) == {"status": 0, "loaded": []}
    after = _loaded_after("fit", "Au", "--export", "gltf", "-o", str(tmp_path / "Au.gltf"), watched=OTHER_COMMANDS)
    assert after["status"] == 0 and "fitting.exports" in after["loaded"]


_THREADS_PROBE = """
import json, runpy, sys, types
def main():  # the command, replaced: what numpy's BLAS runs with once imported after fitting/__main__.py's settings
    import numpy, threadpoolctl
    print(json.dumps([p["num_threads"] for p in threadpoolctl.threadpool_info() if p["user_api"] == "blas"]))
    return 0
sys.modules["fitting.cli.main"] = types.SimpleNamespace(main=main)
runpy.run_module("fitting", run_name="__main__")
"""


@pytest.mark.slow  # starts processes
def test_the_command_runs_one_blas_thread_unless_asked_for_more():
    import os

    env = {
        k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
    }
    runs = [
        subprocess.run(
            [sys.executable, "-c", _THREADS_PROBE], cwd=ROOT, env=e, capture_output=True, text=True, timeout=60
        )
        for e in (env, {**env, "OPENBLAS_NUM_THREADS": "2"})
    ]
    assert [json.loads(r.stdout) for r in runs] == [[1], [2]], [r.stderr for r in runs]
