"""
The three.js material's files as the service serves them: the package's
modules (web/three/src/) at /static/three/, three itself (scripts/three, as the lock pins it) at
/vendor/three/, the example page at /examples/three.html; nothing else of
node_modules is reachable.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LOCK = json.loads((ROOT / "scripts" / "three" / "package-lock.json").read_text())


@pytest.mark.parametrize(
    "path",
    [
        "/static/three/index.js",
        "/static/three/coated_conductor.js",
        "/static/three/albedo_table.js",
        "/static/three/escape_table.js",
        "/static/three/gltf_loader.js",
        "/static/three/gltf_exporter.js",
        "/static/three/packing.js",
        "/static/three/kinds.js",
        "/static/three/generated/glsl.js",
        "/static/three/generated/kinds.js",
        "/static/three/generated/lut.js",
        "/static/three/node_material.js",
        "/static/three/node_models.js",
        "/vendor/three/build/three.webgpu.js",
        "/vendor/three/build/three.tsl.js",
        "/static/glsl.js",
        "/vendor/three/build/three.module.js",
        "/vendor/three/build/three.core.js",
        "/vendor/three/examples/jsm/loaders/GLTFLoader.js",
        "/vendor/three/examples/jsm/environments/RoomEnvironment.js",
        "/examples/three.js",
    ],
)
def test_modules_served_as_javascript(reader, path):
    response = reader.get(path)
    assert response.status_code == 200, path
    assert response.headers["content-type"].startswith(("text/javascript", "application/javascript"))


def test_the_locked_three_is_served(reader):
    want = LOCK["packages"]["node_modules/three"]["version"]
    head = reader.get("/vendor/three/build/three.core.js").text[:400]
    assert "Three.js Authors" in head and LOCK["packages"][""]["dependencies"]["three"] == want
    revision = want.split(".")[1]
    assert f"REVISION = '{revision}'" in reader.get("/vendor/three/build/three.core.js").text


def test_example_page_uses_the_import_map_not_a_cdn(reader):
    page = reader.get("/examples/three.html")
    assert page.status_code == 200
    assert '"three": "/vendor/three/build/three.module.js"' in page.text
    assert "http://" not in page.text and "https://" not in page.text


@pytest.mark.parametrize(
    "path", ["/vendor/three/package.json", "/vendor/three/src/Three.js", "/vendor/three/../../package-lock.json"]
)
def test_only_build_and_addons(reader, path):
    assert reader.get(path).status_code == 404
