"""
A new export format is one file: the toy format of
tests/toy_export_format.py (USD's ``.usda``), loaded with
``COATED_PLUGINS=tests/toy_export_format.py`` and changed nowhere else, is served
by the CLI (``fit --export usda``), by ``GET /api/v1/fits/{id}/pack``, by
``POST /api/v1/packs``, listed by ``GET /api/v1/domain``, and offered and
downloaded by the editor's download menu in Chromium.
"""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import loopback
import pytest
from conftest import run_command, server_process
from editor_pages import chromium, open_editor, pages, settled  # noqa: F401 (fixtures)
from playwright.sync_api import expect

from fitting.exports import EXPORT_FORMATS

pytestmark = [pytest.mark.server, pytest.mark.browser]

TESTS = Path(__file__).resolve().parents[1]
PLUGIN = {"COATED_PLUGINS": str(TESTS / "toy_export_format.py")}
API = "/api/v1"


@pytest.fixture(scope="module")
def toy_server(tmp_path_factory):
    with server_process(tmp_path_factory.mktemp("toy-format") / "data", **PLUGIN) as server:
        yield server


@pytest.fixture(scope="module")
def live_server(toy_server):
    """The editor's server for this module's browser test: the one with the toy format."""
    return toy_server.url


@pytest.fixture(scope="module")
def gold(toy_server):
    with loopback.Client(base_url=toy_server.url, timeout=120) as http:
        answer = http.post(f"{API}/fits", json={"material": "Au"})
        assert answer.status_code in (200, 201), answer.text[:300]
        return answer.json()["id"]


def test_the_toy_is_registered_only_by_its_plugin():
    assert "usda" not in EXPORT_FORMATS  # this process never loaded it


def test_the_cli_writes_the_toy(tmp_path):
    import os

    out = tmp_path / "au.usda"
    done = run_command(
        "fitting", "fit", "Au", "--export", "usda", "--eta-i", "1.33", "-o", str(out), env={**os.environ, **PLUGIN}
    )
    assert done.returncode == 0, done.stderr[-500:]
    text = out.read_text()
    assert text.startswith("#usda 1.0") and "UsdPreviewSurface" in text and "eta_i 1.33" in text
    refused = run_command("fitting", "fit", "Au", "--export", "usda")
    assert refused.returncode == 2 and "invalid choice: 'usda'" in refused.stderr


def test_the_domain_lists_the_toy(toy_server):
    with loopback.Client(base_url=toy_server.url, timeout=60) as http:
        formats = http.get(f"{API}/domain").json()["export_formats"]
    names = [f["name"] for f in formats]
    assert names[:4] == ["mtlx", "openpbr", "blender", "gltf"] and names[-1] == "usda"
    assert formats[-1] == {
        "name": "usda",
        "label": "USD preview surface (.usda)",
        "media_type": "model/vnd.usda",
        "extension": "usda",
        "options": ["eta_i", "roughness", "coat_roughness", "working_space"],
    }


def test_rest_and_packs_serve_the_toy(toy_server, gold):
    with loopback.Client(base_url=toy_server.url, timeout=120) as http:
        one = http.get(f"{API}/fits/{gold}/pack", params={"format": "usda", "eta_i": 1.5, "roughness": 0.4})
        assert one.status_code == 200, one.text[:300]
        assert one.headers["content-type"].startswith("model/vnd.usda")
        assert one.headers["content-disposition"].endswith('-eta1.5-rough0.4-coat0.03.usda"')
        assert b"float inputs:roughness = 0.4" in one.content
        pack = http.post(f"{API}/packs", json={"fit_ids": [gold], "format": "usda", "eta_i": 1.2})
        assert pack.status_code == 200, pack.text[:300]
        with zipfile.ZipFile(io.BytesIO(pack.content)) as archive:
            (name,) = archive.namelist()
            assert name == "Au-eta1.2.usda" and archive.read(name).startswith(b"#usda 1.0")
        for bad in (
            http.get(f"{API}/fits/{gold}/pack", params={"format": "usdz"}),
            http.post(f"{API}/packs", json={"fit_ids": [gold], "format": "usdz"}),
        ):
            assert bad.status_code == 422
            assert (
                "`format` must be one of 'binary', 'json', 'glsl', 'hlsl', 'mtlx', 'openpbr', 'blender', 'gltf', 'glb', 'usda', got 'usdz'"
                in bad.text
            )


def test_the_editor_offers_and_downloads_the_toy(pages, live_server, gold):
    page = pages.new()
    open_editor(page, live_server + "/")
    settled(page)
    expect(page.locator("#export-formats option[value='usda']")).to_have_text("USD preview surface (.usda)")
    page.select_option("#format", "usda")
    expect(page.locator("#download-settings")).to_contain_text("ηᵢ")
    with page.expect_download() as info:
        page.click("#download")
    assert info.value.suggested_filename.endswith(".usda")
    assert open(info.value.path(), "rb").read().startswith(b"#usda 1.0")
