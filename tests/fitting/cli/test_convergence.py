"""The CLI says so when a fit does not converge, and --strict makes it an error."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import run_command


def glass_csv(tmp_path):
    wavelength = np.linspace(350.0, 850.0, 26)
    rows = "\n".join(f"{w},1.5,0" for w in wavelength)
    path = tmp_path / "glass.csv"
    path.write_text("wavelength_nm,n,k\n" + rows + "\n")
    return path


def fit(*args):
    return run_command("fitting", "fit", *args, timeout=600)


@pytest.mark.slow  # 5.9 s (all cases 5.9 s) in a --durations=0 run
def test_non_converged_fit_warns_and_strict_fails(tmp_path):
    path = glass_csv(tmp_path)
    out = tmp_path / "glass.cfpk"
    result = fit("--nk", str(path), "--no-metrics", "-o", str(out))
    assert result.returncode == 0
    assert "warning: the fit of 'glass' did not converge" in result.stderr
    assert out.read_bytes()[:4] == b"CFPK"
    strict_out = tmp_path / "strict.cfpk"
    strict = fit("--nk", str(path), "--no-metrics", "--strict", "-o", str(strict_out))
    assert strict.returncode == 3 and "(--strict)" in strict.stderr
    assert not strict_out.exists()


@pytest.mark.slow  # 2.8 s (all cases 2.8 s) in a --durations=0 run
def test_converged_fit_is_quiet_under_strict(tmp_path):
    # Weaver's tungsten: sampled every 26 nm at most, no data warning.
    result = fit("W", "--no-metrics", "--strict", "-o", str(tmp_path / "w.cfpk"))
    assert result.returncode == 0, result.stderr
    assert "warning" not in result.stderr and "did not converge" not in result.stderr
