"""
The Babylon.js package's files as the service serves them: its modules
(web/babylon/src/) at /static/babylon/, Babylon.js itself (scripts/babylon,
as the lock pins it) at /vendor/babylon/core/ and /vendor/babylon/loaders/,
the example page at /examples/babylon.html, with an import map and no CDN.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LOCK = json.loads((ROOT / "scripts" / "babylon" / "package-lock.json").read_text())


@pytest.mark.parametrize(
    "path",
    [
        "/static/babylon/index.js",
        "/static/babylon/coated_conductor.js",
        "/static/babylon/gltf_loader.js",
        "/static/babylon/check_model.js",
        "/static/babylon/generated/glsl.js",
        "/vendor/babylon/core/Materials/materialPluginBase.js",
        "/vendor/babylon/core/Engines/engine.js",
        "/vendor/babylon/loaders/glTF/2.0/glTFLoader.js",
        "/vendor/babylon/loaders/glTF/index.js",
        "/examples/babylon.js",
    ],
)
def test_modules_served_as_javascript(reader, path):
    response = reader.get(path)
    assert response.status_code == 200, path
    assert response.headers["content-type"].startswith(("text/javascript", "application/javascript"))


def test_the_locked_babylon_is_served(reader):
    for name in ("core", "loaders"):
        want = LOCK["packages"][f"node_modules/@babylonjs/{name}"]["version"]
        assert LOCK["packages"][""]["dependencies"][f"@babylonjs/{name}"] == want
        served = reader.get(f"/vendor/babylon/{name}/package.json")
        assert served.status_code == 200 and served.json()["version"] == want


def test_example_page_uses_the_import_map_not_a_cdn(reader):
    page = reader.get("/examples/babylon.html")
    assert page.status_code == 200
    assert '"@babylonjs/core/": "/vendor/babylon/core/"' in page.text
    assert "http://" not in page.text and "https://" not in page.text
