"""
The colour controls' conversions in the browser (``static/editor/colour.js``,
run by node) against colour-science: sRGB hex to linear Rec.709
(``colour.cctf_decoding(..., "sRGB")``), linear Rec.709 to hex (its
``cctf_encoding``, rounded to 8 bits), and linear Rec.709 <-> linear ACEScg
(``colour.RGB_to_RGB`` with CAT02, the service's conversion of ``f0`` and
``f82``). The same formulas in float64: the transfer functions within 1e-12
(one ``**`` of a double each side), the matrices, printed in colour.js to 17
digits, within 1e-12 on colours in [0, 1] (a row of three products, each
rounded at 1e-16 relative); hex exactly.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fitting.colour.colorimetry import colour_science

pytestmark = pytest.mark.slow  # starts a process (node)

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = """
import { ACEScgToRec709, hexToLinear, linearToHex, rec709ToACEScg } from "./static/editor/colour.js";
const { hexes, linear } = JSON.parse(process.argv[1]);
console.log(JSON.stringify({
  decoded: hexes.map(hexToLinear),
  encoded: linear.map(linearToHex),
  acescg: linear.map(rec709ToACEScg),
  back: linear.map(ACEScgToRec709),
}));
"""


def browser(hexes: list[str], linear: np.ndarray) -> dict:
    node = shutil.which("node")
    assert node, "node is needed for the editor's unit tests (docs/testing.md)"
    done = subprocess.run(
        [node, "--input-type=module", "-e", SCRIPT, json.dumps({"hexes": hexes, "linear": linear.tolist()})],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    return json.loads(done.stdout)


def test_conversions_match_colour_science():
    colour = colour_science()
    rng = np.random.default_rng(51)
    codes = rng.integers(0, 256, (200, 3))
    codes[:3] = [[0, 0, 0], [255, 255, 255], [10, 11, 12]]  # black, white, the linear segment
    hexes = ["#" + "".join(f"{v:02x}" for v in c) for c in codes]
    linear = rng.uniform(0.0, 1.0, (200, 3))
    linear[:2] = [[0.0, 0.0, 0.0], [0.002, 0.003, 1.0]]
    got = browser(hexes, linear)

    np.testing.assert_allclose(got["decoded"], colour.cctf_decoding(codes / 255.0, function="sRGB"), rtol=0, atol=1e-12)
    expected_hex = [
        "#" + "".join(f"{int(round(v)):02x}" for v in c) for c in 255.0 * colour.cctf_encoding(linear, function="sRGB")
    ]
    assert got["encoded"] == expected_hex
    to_acescg = colour.RGB_to_RGB(linear, "ITU-R BT.709", "ACEScg", chromatic_adaptation_transform="CAT02")
    np.testing.assert_allclose(got["acescg"], to_acescg, rtol=0, atol=1e-12)
    to_rec709 = colour.RGB_to_RGB(linear, "ACEScg", "ITU-R BT.709", chromatic_adaptation_transform="CAT02")
    np.testing.assert_allclose(got["back"], to_rec709, rtol=0, atol=1e-12)
