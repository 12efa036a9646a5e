"""
What a command's start imports: ``python -m fitting fit`` of a coated-conductor
material never imports scipy.optimize, scipy.interpolate or colour-science
(most of a start: their import took about 1 s of a 30 ms fit); the commands that need them
import them when they run.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
HEAVY = ("scipy.optimize", "scipy.interpolate", "colour", "matplotlib")

_PROBE = """
import contextlib, io, json, sys
from fitting.cli.main import main
with contextlib.redirect_stdout(io.StringIO()):
    status = main(sys.argv[1:])
print(json.dumps({"status": status, "loaded": [m for m in %r if m in sys.modules]}))
""" % (HEAVY,)


def _loaded_after(*args: str) -> dict:
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, *args], cwd=ROOT, capture_output=True, text=True, timeout=120, check=True
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
