"""
What the three.js package's inside split-sum table costs
========================================================

coated-conductor-three (web/three/) carries the split-sum LUT that GET
/api/v1/ibl-lut serves (16 x 64 x 64 x (A, B, G) float32) inside its
generated/lut.js: A and B once (they repeat across the alpha slices), G,
float32 in byte planes, deflated and base64 (``python -m
preview_shaders.three_package``); it is inflated on first use, losslessly.

Sizes (bytes): the served file, the table's texels, the package's planes,
deflated, the module lut.js, the module gzipped (what a server that
compresses sends), the GLSL module glsl.js, and the package's src/ in all.

Start-up in Chromium (the tests' switches, editor_pages.launch), the
package and three served by http.server on 127.0.0.1, a fresh context each
round (``--rounds``, default 8, after one not counted): ``import_ms`` the
import of generated/lut.js (fetching and parsing its string),
``decode_ms`` its ``lutTexels()`` (base64, inflate, planes to texels) and
``resources_ms`` the package's ``loadResources()`` after it (what the first
material waits for: the LUT decoded again, the patched chunk and the RGBA 3D
texture), median and worst; the texture's upload is a frame's.
Records benchmarks/results/three_package.json::

    .venv/bin/python benchmarks/three_package.py [--rounds N]
"""

from __future__ import annotations

import argparse
import functools
import gzip
import http.server
import statistics
import sys
import tempfile
import threading
import zlib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "static"))

from benchmarks.record import load_average, write_result  # noqa: E402
from editor_pages import launch  # noqa: E402
from fitting.shading.lut import default_lut, encode_lut  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402
from preview_shaders.three_package import OUT, lut_planes  # noqa: E402

SRC = ROOT / "web" / "three" / "src"
THREE = ROOT / "scripts" / "three" / "node_modules" / "three"

PAGE = """<!doctype html><html><head><meta charset="utf-8"><link rel="icon" href="data:,">
<script type="importmap">{"imports": {"three": "/three/build/three.module.js"}}</script>
</head><body></body></html>"""

MEASURE = """async () => {
    let t = performance.now();
    const { lutTexels } = await import('/package/lut.js');
    const import_ms = performance.now() - t;
    t = performance.now();
    const lut = await lutTexels();
    const decode_ms = performance.now() - t;
    const { loadResources } = await import('/package/index.js');
    t = performance.now();
    const resources = await loadResources();
    const resources_ms = performance.now() - t;
    return { import_ms, decode_ms, resources_ms, texels: lut.data.length, width: resources.lut.width };
}"""


class Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


def sizes() -> dict:
    lut = default_lut()
    planes = lut_planes(lut.data)
    package = sorted(p for p in SRC.rglob("*") if p.is_file())
    return {
        "served_file": len(encode_lut(lut)),
        "texels": lut.data.astype("<f4").nbytes,
        "planes": len(planes),
        "deflated": len(zlib.compress(planes, 9)),
        "lut_module": (OUT / "lut.js").stat().st_size,
        "lut_module_gzip": len(gzip.compress((OUT / "lut.js").read_bytes(), 9)),
        "glsl_module": (OUT / "glsl.js").stat().st_size,
        "package_src": sum(p.stat().st_size for p in package),
        "package_src_gzip": sum(len(gzip.compress(p.read_bytes(), 9)) for p in package),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=8)
    args = parser.parse_args()
    load = load_average()
    figures = {"bytes": sizes()}
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        (root / "package").symlink_to(SRC, target_is_directory=True)
        (root / "three").symlink_to(THREE, target_is_directory=True)
        (root / "index.html").write_text(PAGE)
        server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=tmp))
        threading.Thread(target=server.serve_forever, daemon=True).start()
        url = f"http://127.0.0.1:{server.server_address[1]}/index.html"
        rounds = []
        try:
            with sync_playwright() as p:
                browser = launch(p)
                for i in range(args.rounds + 1):
                    context = browser.new_context()
                    page = context.new_page()
                    page.goto(url)
                    result = page.evaluate(MEASURE)
                    context.close()
                    if i:
                        rounds.append(result)
                browser.close()
        finally:
            server.shutdown()
            server.server_close()
    for key in ("import_ms", "decode_ms", "resources_ms"):
        values = [r[key] for r in rounds]
        figures[key] = {"median": statistics.median(values), "max": max(values)}
    figures["texels"] = rounds[0]["texels"]
    path = write_result("three_package", figures, load, rounds=args.rounds)
    for name, value in figures["bytes"].items():
        print(f"{name:>18}: {value:>9,d} bytes")
    for key in ("import_ms", "decode_ms", "resources_ms"):
        print(f"{key:>18}: median {figures[key]['median']:.1f} ms, worst {figures[key]['max']:.1f} ms")
    print(f"recorded {path.relative_to(ROOT)} (load average {load})")


if __name__ == "__main__":
    main()
