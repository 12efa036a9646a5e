"""
Finite in, finite out: 20 extreme but finite n, k tables (``benchmarks/finite_inputs.py``:
n and k from 1e-6 to 1e200, everywhere or at one sample) get the same answer from the
command line and from a real server process: refused by the same rule (n or k above
1000 where the fit uses them), or fitted to the same float16 coefficients with the
same warnings; every output is strict JSON, every figure finite. ``--strict`` fails
on any warning.
"""

from __future__ import annotations

import json
import math

import pytest

from benchmarks.finite_inputs import CASES, _rule, _strict_json, run_service, same_answer
from conftest import run_command, server_process

pytestmark = [pytest.mark.slow, pytest.mark.server]


def _cli(table, directory, *extra):
    w, n, k = table
    path = directory / "case.csv"
    path.write_text(
        "wavelength_nm,n,k\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(w, n, k))
    )
    return run_command("fitting", "fit", "--nk", str(path), "--name", "case", "--json", *extra)


@pytest.mark.slow  # 20 CLI fits and 20 service fits: about 60 s on the shared 2 cores
def test_cli_and_service_agree_on_20_extreme_tables(tmp_path):
    assert len(CASES) == 20
    answers = {}
    with server_process(tmp_path / "data") as server:
        for name, table in CASES.items():
            done = _cli(table, tmp_path)
            if done.returncode == 0:
                view = _strict_json(done.stdout)  # raises on NaN or infinity
                cli = {
                    "accepted": True,
                    "coefficients": view["coefficients"],
                    "warnings": view["fit"].get("quality", {}).get("warnings", []),
                    "delta_E_mean": view["metrics"]["figure"]["delta_E_mean"],
                }
            else:
                assert done.returncode == 2, (name, done.stderr)
                cli = {"accepted": False, "rule": _rule(done.stderr.strip().splitlines()[-1])}
            service = run_service(server.url, name, table)
            answers[name] = (cli, service)
            assert same_answer(cli, service), (name, cli, service)
            for answer in (cli, service):
                if answer["accepted"]:
                    assert math.isfinite(answer["delta_E_mean"]), name
    refused = {name for name, (cli, _) in answers.items() if not cli["accepted"]}
    assert refused == {
        "k 1001 everywhere",
        "k 1e6 everywhere",
        "n 1e200 everywhere",
        "k 1e20 at 550 nm",
        "k 1e200 at 550 nm",
        "n 1e200 at 550 nm",
        "n 1e6 at 550 nm",
        "n 1e200 at 350 nm, the nearest beyond 360 nm",
    }
    for name in refused:
        assert answers[name][0]["rule"].startswith(("`n` must be at most 1000", "`k` must be at most 1000"))
    spikes = ("n 50 at 550 nm", "k 300 at 550 nm", "k 1e-6 at 550 nm", "n 1e-6 at 550 nm")
    for name in spikes:  # inside the range, off its neighbours: fitted, the outlier named with its wavelength
        assert any(w.startswith("outlier") and "at 550 nm" in w for w in answers[name][0]["warnings"]), name


@pytest.mark.slow  # starts processes
def test_strict_fails_on_an_outlier_and_writes_valid_json_otherwise(tmp_path):
    strict = _cli(CASES["n 50 at 550 nm"], tmp_path, "--strict")
    assert strict.returncode == 3 and "outlier: n = 50 at 550 nm" in strict.stderr
    assert strict.stdout == ""
    loose = _cli(CASES["n 50 at 550 nm"], tmp_path)
    assert loose.returncode == 0 and "warning: outlier: n = 50 at 550 nm" in loose.stderr
    json.loads(loose.stdout, parse_constant=lambda token: pytest.fail(f"not JSON: {token}"))
