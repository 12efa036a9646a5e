"""
Write the sample asset of EXT_materials_coated_conductor
========================================================

``docs/gltf/samples/CoatedConductorGrid/`` in the layout of Khronos'
glTF-Sample-Assets: ``glTF/`` (``.gltf`` + ``.bin``), ``glTF-Binary/``
(``.glb``), ``screenshot/screenshot.jpg`` and ``README.md``. A grid of
spheres, a column per metal of the library (its spectral n, k, fitted with
the ``coated-conductor`` model over eta_i 1 to 2.5, the service's default
kind) and a row per coat index, each material as the glTF export writes it
(:mod:`fitting.exports.gltf_grid`). The screenshot is drawn by three.js
through the package ``coated-conductor-three`` in Chromium (headless, the
Debian ``chromium``; python playwright), from a plain static folder, under
three's ``RoomEnvironment``.

    .venv/bin/python benchmarks/coated_conductor_grid.py [--out DIR] [--no-screenshot]
"""

from __future__ import annotations

import argparse
import functools
import http.server
import json
import shutil
import sys
import tempfile
import threading
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from fitting.exports import export_values  # noqa: E402
from fitting.exports.gltf_grid import grid_asset, grid_glb, grid_gltf  # noqa: E402
from fitting.fits.kinds import fit_model  # noqa: E402
from fitting.optics.library import library_material  # noqa: E402

NAME = "CoatedConductorGrid"
OUT = ROOT / "docs" / "gltf" / "samples" / NAME
METALS = ("Au", "Cu", "CuZn", "Ag", "Al", "Cr")
COAT_INDICES = (1.0, 1.33, 1.5, 2.0)
ETA_RANGE = (1.0, 2.5)
ROUGHNESS, COAT_ROUGHNESS = 0.2, 0.03
KIND = "coated-conductor"
SIZE = (960, 640)
GENERATOR = "coated-fresnel benchmarks/coated_conductor_grid.py"
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]

PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>CoatedConductorGrid</title><link rel="icon" href="data:,">
<script type="importmap">{"imports": {"three": "./node_modules/three/build/three.module.js",
  "three/addons/": "./node_modules/three/examples/jsm/",
  "coated-conductor-three": "./node_modules/coated-conductor-three/src/index.js"}}</script>
<style>html, body { margin: 0; background: #202124; }</style>
<script type="module">
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { RoomEnvironment } from "three/addons/environments/RoomEnvironment.js";
import { CoatedConductorExtension } from "coated-conductor-three";

const [width, height] = SIZE;
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setSize(width, height);
renderer.toneMapping = THREE.NeutralToneMapping;
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x202124);
const pmrem = new THREE.PMREMGenerator(renderer);
scene.environment = pmrem.fromScene(new RoomEnvironment(), 0.04).texture;
const loader = new GLTFLoader();
loader.register((parser) => new CoatedConductorExtension(parser));
const gltf = await loader.loadAsync("NAME.glb");
scene.add(gltf.scene);
let drawn = 0;
gltf.scene.traverse((o) => { if (o.isMesh && o.material.userData.coatedConductor) drawn += 1; });
const camera = new THREE.PerspectiveCamera(30, width / height, 0.1, 100);
camera.position.set(0, 0, 23);
camera.lookAt(0, 0, 0);
renderer.render(scene, camera);
document.body.dataset.drawn = String(drawn);
</script></head><body></body></html>
"""


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


def build(out: Path) -> dict:
    """Fit, export and write the asset's files under ``out``; the asset (JSON)."""
    rows = [[] for _ in COAT_INDICES]
    for metal in METALS:
        nk = library_material(metal)
        packed = fit_model(nk, ETA_RANGE, KIND).packed
        for r, eta in enumerate(COAT_INDICES):
            rows[r].append(
                export_values(
                    nk, eta, roughness=ROUGHNESS, coat_roughness=COAT_ROUGHNESS, model=packed, tools=("gltf",)
                )
            )
    asset, buffer = grid_asset(rows, GENERATOR)
    text, binary = grid_gltf(asset, buffer, f"{NAME}.bin")
    (out / "glTF").mkdir(parents=True, exist_ok=True)
    (out / "glTF-Binary").mkdir(parents=True, exist_ok=True)
    (out / "glTF" / f"{NAME}.gltf").write_text(text)
    (out / "glTF" / f"{NAME}.bin").write_bytes(binary)
    (out / "glTF-Binary" / f"{NAME}.glb").write_bytes(grid_glb(asset, buffer))
    return asset


def screenshot(out: Path) -> int:
    """Draw the GLB with three.js and the package in Chromium; write screenshot/screenshot.jpg; spheres drawn."""
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory(prefix="ccgrid-") as folder:
        root = Path(folder)
        (root / "node_modules").mkdir()
        (root / "node_modules" / "three").symlink_to(ROOT / "scripts" / "three" / "node_modules" / "three")
        (root / "node_modules" / "coated-conductor-three").symlink_to(ROOT / "web" / "three")
        shutil.copy(out / "glTF-Binary" / f"{NAME}.glb", root / f"{NAME}.glb")
        (root / "index.html").write_text(PAGE.replace("SIZE", json.dumps(list(SIZE))).replace("NAME", NAME))
        server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=folder))
        threading.Thread(target=server.serve_forever, daemon=True).start()
        try:
            with sync_playwright() as p:
                browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=CHROMIUM_ARGS)
                try:
                    page = browser.new_page(viewport={"width": SIZE[0], "height": SIZE[1]})
                    errors = []
                    page.on("pageerror", lambda error: errors.append(str(error)))
                    page.goto(f"http://127.0.0.1:{server.server_address[1]}/index.html")
                    page.wait_for_function("document.body.dataset.drawn", timeout=300_000)
                    if errors:
                        raise RuntimeError(f"the page failed: {errors}")
                    (out / "screenshot").mkdir(parents=True, exist_ok=True)
                    page.locator("canvas").screenshot(
                        path=str(out / "screenshot" / "screenshot.jpg"), type="jpeg", quality=88
                    )
                    return int(page.evaluate("document.body.dataset.drawn"))
                finally:
                    browser.close()
        finally:
            server.shutdown()
            server.server_close()


README = """# Coated Conductor Grid

## Screenshot

![screenshot](screenshot/screenshot.jpg)

Drawn by three.js r187 with the package `coated-conductor-three` (its
`GLTFLoader` plugin) under three's `RoomEnvironment`, neutral tone mapping.

## Description

A grid of spheres for `EXT_materials_coated_conductor`
([specification](../../EXT_materials_coated_conductor/README.md)): a column
per metal, {metals}, left to right, and a row per coat index,
{indices}, top to bottom (1: no coat, the bare metal). Each metal is this
project's `{kind}` fit of its spectral n, k over coat indices
{lo:g} to {hi:g}; metal roughness {roughness:g}, coat roughness {coat:g}. Each
material carries:

- `EXT_materials_coated_conductor`: the metal, the model's float16
  coefficients;
- `KHR_materials_clearcoat` (`clearcoatFactor` 1) with the coat's index in the
  nested draft `KHR_materials_clearcoat_ior` (none at index 1);
- the fallback's `baseColorFactor`, fitted to the coated metal as three.js
  draws glTF's clear coat;
- `extras.coated_fresnel`: where the values come from (the fit, its pack).

A viewer without the extension draws the fallback. Node names are
`<metal> eta_i <index>`.

## Files

- `glTF/{name}.gltf` and `glTF/{name}.bin`
- `glTF-Binary/{name}.glb`

Written by `benchmarks/coated_conductor_grid.py`; the Khronos glTF validator
reports no error and no warning on both
(`tests/fitting/exports/test_gltf_grid.py`).

## License

The same licence as this repository.
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="benchmarks/coated_conductor_grid.py", description=__doc__.splitlines()[1])
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument("--no-screenshot", action="store_true")
    args = parser.parse_args(argv)
    asset = build(args.out)
    (args.out / "README.md").write_text(
        README.format(
            metals=", ".join(METALS),
            indices=", ".join(f"{e:g}" for e in COAT_INDICES),
            kind=KIND,
            lo=ETA_RANGE[0],
            hi=ETA_RANGE[1],
            roughness=ROUGHNESS,
            coat=COAT_ROUGHNESS,
            name=NAME,
        )
    )
    print(f"{len(asset['materials'])} materials written to {args.out}")
    if not args.no_screenshot:
        drawn = screenshot(args.out)
        print(f"screenshot: {drawn} spheres drawn with the extension")
        if drawn != len(asset["materials"]):
            print(f"expected {len(asset['materials'])} drawn with the extension", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
