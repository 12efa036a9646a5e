"""
Finite in, finite out: 20 extreme but finite n, k tables through the CLI and the service.

Each case (:data:`CASES`: n and k from 1e-6 to 1e200, everywhere or at one
sample, inside the visible range or beyond it) is fitted by the command
line (``python -m fitting fit --nk FILE.csv --json``) and by a real server
process (``POST /api/v1/fits``); the record says per case what each
answered (refused with which rule, or the coefficients and the warnings),
whether both agree, and whether every output parsed as strict JSON (no
NaN or infinity).

Writes benchmarks/results/finite_inputs.json.

Usage: python benchmarks/finite_inputs.py
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import httpx
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.record import load_average, write_result  # noqa: E402
from benchmarks.serve import start_replicas  # noqa: E402

WAVELENGTH_NM = np.arange(350.0, 851.0, 10.0)
"""The base table: a smooth metal (n 0.4-0.8, k 2-4.5) every 10 nm over 350-850 nm."""


def _base() -> tuple[np.ndarray, np.ndarray]:
    t = (WAVELENGTH_NM - 350.0) / 500.0
    return 0.4 + 0.4 * t, 2.0 + 2.5 * t


def _case(n=None, k=None, at=None, n_at=None, k_at=None, extra=None, drop=None):
    n0, k0 = _base()
    n1 = n0.copy() if n is None else np.full_like(n0, n)
    k1 = k0.copy() if k is None else np.full_like(k0, k)
    if at is not None:
        i = int(np.argmin(np.abs(WAVELENGTH_NM - at)))
        if n_at is not None:
            n1[i] = n_at
        if k_at is not None:
            k1[i] = k_at
    w = WAVELENGTH_NM
    if drop is not None:  # one sample removed (the data then reach past 360 nm by their first sample)
        keep = w != drop
        w, n1, k1 = w[keep], n1[keep], k1[keep]
    if extra is not None:  # one sample added beyond the visible range: (wavelength, n, k)
        w, n1, k1 = np.append(w, extra[0]), np.append(n1, extra[1]), np.append(k1, extra[2])
    return w, n1, k1


CASES: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {
    "k 1e-6 everywhere (n 1.5)": _case(n=1.5, k=1e-6),
    "n 1e-6 everywhere": _case(n=1e-6),
    "n and k 1e-6 everywhere": _case(n=1e-6, k=1e-6),
    "k 1e3 everywhere": _case(k=1e3),
    "n 1e3 everywhere": _case(n=1e3),
    "n and k 1e3 everywhere": _case(n=1e3, k=1e3),
    "n 1e-6, k 999 everywhere": _case(n=1e-6, k=999.0),
    "k 1001 everywhere": _case(k=1001.0),
    "k 1e6 everywhere": _case(k=1e6),
    "n 1e200 everywhere": _case(n=1e200),
    "k 1e20 at 550 nm": _case(at=550, k_at=1e20),
    "k 1e200 at 550 nm": _case(at=550, k_at=1e200),
    "n 1e200 at 550 nm": _case(at=550, n_at=1e200),
    "n 1e6 at 550 nm": _case(at=550, n_at=1e6),
    "n 50 at 550 nm": _case(at=550, n_at=50.0),
    "k 300 at 550 nm": _case(at=550, k_at=300.0),
    "k 1e-6 at 550 nm": _case(at=550, k_at=1e-6),
    "n 1e-6 at 550 nm": _case(at=550, n_at=1e-6),
    "k 1e200 at 2000 nm (unused)": _case(extra=(2000.0, 1.0, 1e200)),
    "n 1e200 at 350 nm, the nearest beyond 360 nm": _case(at=350, n_at=1e200, drop=360.0),
}
"""20 extreme but finite tables, by what they hold."""


def _strict_json(text: str):
    """``text`` parsed as JSON that holds no NaN or infinity (ValueError otherwise)."""

    def refuse(token):
        raise ValueError(f"not JSON: {token}")

    return json.loads(text, parse_constant=refuse)


def _rule(message: str) -> str:
    """The rule of a refusal, without the value and where (the two answers word those alike)."""
    return message.split(", got")[0].split("error: ")[-1].strip()


def run_cli(name: str, table, directory: Path) -> dict:
    w, n, k = table
    path = directory / "case.csv"
    path.write_text(
        "wavelength_nm,n,k\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(w, n, k))
    )
    done = subprocess.run(
        [sys.executable, "-m", "fitting", "fit", "--nk", str(path), "--name", "case", "--json"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    if done.returncode != 0:
        return {
            "accepted": False,
            "exit": done.returncode,
            "rule": _rule(done.stderr.strip().splitlines()[-1]),
            "json_valid": True,
        }
    view = _strict_json(done.stdout)
    return {
        "accepted": True,
        "coefficients": view["coefficients"],
        "warnings": view["fit"].get("quality", {}).get("warnings", []),
        "delta_E_mean": view["metrics"]["figure"]["delta_E_mean"],
        "json_valid": True,
    }


def run_service(url: str, name: str, table) -> dict:
    w, n, k = table
    body = {"name": "case", "nk": {"wavelength_nm": w.tolist(), "n": n.tolist(), "k": k.tolist()}}
    response = httpx.post(f"{url}/api/v1/fits?metrics=full", json=body, timeout=600)
    answer = _strict_json(response.text)
    if response.status_code >= 400:
        detail = answer.get("detail")
        message = detail if isinstance(detail, str) else json.dumps(detail)
        return {"accepted": False, "status": response.status_code, "rule": _rule(message), "json_valid": True}
    details = answer["metrics"]["details"]
    return {
        "accepted": True,
        "status": response.status_code,
        "coefficients": answer["coefficients"],
        "warnings": details.get("quality", {}).get("warnings", []),
        "delta_E_mean": answer["metrics"]["figure"]["delta_E_mean"],
        "json_valid": True,
    }


def same_answer(cli: dict, service: dict) -> bool:
    """Both refuse by the same rule, or both fit the same float16 coefficients with the same warnings."""
    if cli["accepted"] != service["accepted"]:
        return False
    if not cli["accepted"]:
        return cli["rule"] == service["rule"] or cli["rule"] in service["rule"]
    return cli["coefficients"] == service["coefficients"] and cli["warnings"] == service["warnings"]


def start_server(data: str) -> tuple[subprocess.Popen, str]:
    """One server with one fit worker (:func:`benchmarks.serve.start_replicas`: a start whose
    port was taken is tried again on another)."""
    ((process, url),) = start_replicas(1, {**os.environ, "COATED_FIT_WORKERS": "1"}, data)
    return process, url


def main() -> int:
    load = load_average()
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        process, url = start_server(f"{tmp}/data")
        try:
            for name, table in CASES.items():
                cli = run_cli(name, table, Path(tmp))
                service = run_service(url, name, table)
                finite = all(math.isfinite(x["delta_E_mean"]) for x in (cli, service) if x["accepted"])
                rows[name] = {"cli": cli, "service": service, "same": same_answer(cli, service), "finite": finite}
                print(
                    f"{name:48s} cli {'fit' if cli['accepted'] else 'refused':7s} service "
                    f"{'fit' if service['accepted'] else 'refused':7s} same {rows[name]['same']}",
                    flush=True,
                )
        finally:
            process.terminate()
            process.wait(30)
    figures = {
        "cases": len(rows),
        "same_answer": sum(r["same"] for r in rows.values()),
        "accepted": sum(r["cli"]["accepted"] for r in rows.values()),
        "refused": sum(not r["cli"]["accepted"] for r in rows.values()),
        "finite_figures": sum(r["finite"] for r in rows.values()),
        "valid_json": sum(r["cli"]["json_valid"] and r["service"]["json_valid"] for r in rows.values()),
        "outlier_warned": sum(
            any(w.startswith("outlier") for w in r["cli"].get("warnings", [])) for r in rows.values()
        ),
    }
    path = write_result("finite_inputs", figures, load, cases=rows)
    print(f"wrote {path}: {figures}")
    return 0 if figures["same_answer"] == figures["cases"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
