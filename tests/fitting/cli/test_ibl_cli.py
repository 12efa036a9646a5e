"""``python -m fitting ibl`` and ``ibl-lut`` as the issue's checks call them."""

from __future__ import annotations

import json

import numpy as np

import pytest
from conftest import run_command

from fitting.shading.ibl import decode_lut


def _run(*args, timeout=600):
    return run_command("fitting", *args, timeout=timeout)


@pytest.mark.slow  # 3.6 s (all cases 3.6 s) in a --durations=0 run
def test_ibl_json_shape_and_agreement():
    out = _run(
        "ibl", "Cr", "--eta-i", "1.5", "--roughness", "0.4", "--json", "--n-dot-v", "0.05,0.3,0.8", "--samples", "8192"
    )
    assert out.returncode == 0, out.stderr
    view = json.loads(out.stdout)
    assert list(view) == ["n_dot_v", "split_sum", "monte_carlo", "monte_carlo_stderr", "reference"]
    assert view["n_dot_v"] == [0.05, 0.3, 0.8]
    split, mc, se, ref = (np.array(view[k]) for k in list(view)[1:])
    assert split.shape == mc.shape == se.shape == ref.shape == (3, 3)
    error = np.abs(split - mc)
    assert np.all((error <= 0.01 * mc) | (error <= 3 * se))
    # The fit is within a few per cent of the spectral reference.
    assert np.all(np.abs(ref - mc) <= 0.05 * ref)


@pytest.mark.slow  # 5.2 s (all cases 5.2 s) in a --durations=0 run
def test_ibl_coated_at_eta_1_and_bad_input():
    out = _run(
        "ibl",
        "Au",
        "--eta-i",
        "1",
        "--roughness",
        "0.2",
        "--mode",
        "coated",
        "--json",
        "--n-dot-v",
        "0.5",
        "--samples",
        "1024",
    )
    assert out.returncode == 0, out.stderr
    assert len(json.loads(out.stdout)["split_sum"]) == 1
    bad = _run("ibl", "Au", "--eta-i", "0.8", "--json")
    assert bad.returncode == 2 and "`eta_i` must lie in [1, 3], got 0.8" in bad.stderr
    bad = _run("ibl", "Au", "--roughness", "2")
    assert bad.returncode == 2 and "--roughness must lie in [0, 1]" in bad.stderr


@pytest.mark.slow  # starts a process or GL context
def test_ibl_lut_file(tmp_path):
    path = tmp_path / "lut.bin"
    out = _run("ibl-lut", "-o", str(path))
    assert out.returncode == 0, out.stderr
    lut = decode_lut(path.read_bytes())
    assert lut.shape == (16, 64, 64)
