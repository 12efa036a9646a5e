"""
Compare mode's Delta E 2000 in the browser (``static/editor/compare.js``,
run by node) against the Python the fits are scored with
(:func:`fitting.colour.delta_e.delta_E_map`: ACEScg to L*a*b* with the ACES
white, colour-science's CIEDE2000), on random linear ACEScg pairs in
[0, 1] (reflectances), greys and equal colours among them. The two are the
same formulas in float64, evaluated in another order (cube roots, hue
angles): bound 1e-6 absolute (measured 4.8e-7 on Delta E near 40, a
relative 1.2e-8).
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fitting.colour.delta_e import delta_E_map

pytestmark = pytest.mark.slow  # starts a process (node)

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = """
import { curvesDeltaE, ACEScg_to_Lab, delta_E_2000 } from "./static/editor/compare.js";
const { a, b } = JSON.parse(process.argv[1]);
const each = a.map((x, i) => delta_E_2000(ACEScg_to_Lab(x), ACEScg_to_Lab(b[i])));
const whole = curvesDeltaE(a, b, a.map((_, i) => i));
console.log(JSON.stringify({ each, whole }));
"""


def browser_delta_E(a: np.ndarray, b: np.ndarray) -> dict:
    node = shutil.which("node")
    assert node, "node is needed for the editor's unit tests (docs/testing.md)"
    done = subprocess.run(
        [node, "--input-type=module", "-e", SCRIPT, json.dumps({"a": a.tolist(), "b": b.tolist()})],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    return json.loads(done.stdout)


class TestCompareDeltaE:
    def test_random_reflectances_match_python(self):
        rng = np.random.default_rng(24)
        a = rng.uniform(0.0, 1.0, (400, 3))
        b = np.clip(a + rng.normal(0.0, 0.05, a.shape), 0.0, 1.0)
        b[:20] = a[:20]  # equal colours: 0
        b[20:40] = b[20:40, :1]  # greys (achromatic): no hue
        got = browser_delta_E(a, b)
        expected = delta_E_map(a, b)
        np.testing.assert_allclose(got["each"], expected, rtol=0, atol=1e-6)
        assert got["whole"]["mean"] == pytest.approx(expected.mean(), abs=1e-6)
        assert got["whole"]["max"] == pytest.approx(expected.max(), abs=1e-6)
        assert got["whole"]["atDeg"] == int(np.argmax(expected))
