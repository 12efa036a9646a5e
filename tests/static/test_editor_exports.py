"""
Every download from the editor, in a real Chromium against a real server:
binary, JSON, GLSL and HLSL packs and the MaterialX, OpenPBR,
Blender and glTF exports, each at the preview's eta_i, roughness and coat
roughness, each arriving under a name that says what it is; and saving
again the material one saved (or opened) continues it: the next version,
no "Replace it?" question.
"""

from __future__ import annotations

import json
import re

import pytest
from editor_pages import editor_url, key_edit, open_editor, pages, chromium, live_server, settled  # noqa: F401 (fixtures: one server and one Chromium a module)
from playwright.sync_api import expect

pytestmark = [pytest.mark.server, pytest.mark.browser]


def set_range(page, selector, value):
    page.eval_on_selector(selector, "(el, v) => { el.value = v; el.dispatchEvent(new Event('input', {bubbles: true})); }",
                          str(value))


# What each format's file is called and what its content must hold.
EXPORT_STEM = r"Au-[0-9a-f]{8}-eta1\.33-rough0\.35-coat0\.1"
FORMATS = {
    "binary": (r"Au-[0-9a-f]{8}\.cfpk", lambda b: b[:4] == b"CFPK"),  # fitting.models.pack.PACK_MAGIC
    "json": (r"Au-[0-9a-f]{8}\.json", lambda b: b"Au" in b and isinstance(json.loads(b), dict)),
    "glsl": (r"Au-[0-9a-f]{8}\.glsl", lambda b: b"vec3" in b),
    "hlsl": (r"Au-[0-9a-f]{8}\.hlsl", lambda b: b"float3" in b),
    "mtlx": (EXPORT_STEM + r"\.mtlx", lambda b: b"<materialx" in b and b"0.35" in b),
    "openpbr": (EXPORT_STEM + r"\.openpbr\.mtlx", lambda b: b"open_pbr_surface" in b and b"0.35" in b),
    "blender": (EXPORT_STEM + r"\.py", lambda b: b"import bpy" in b and b"0.35" in b),
    "gltf": (EXPORT_STEM + r"\.gltf", lambda b: "asset" in json.loads(b)),
}


def test_every_format_downloads_with_the_preview_settings(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    set_range(page, "#eta", 1.33)
    set_range(page, "#roughness", 0.35)
    page.check("#coat")
    set_range(page, "#coat-roughness", 0.1)
    expect(page.locator("#plot")).to_have_attribute("data-eta", "1.33")
    got = {}
    for format, (name, valid) in FORMATS.items():
        page.select_option("#format", format)
        with page.expect_download() as info:
            page.click("#download")
        download = info.value
        body = open(download.path(), "rb").read()
        got[format] = download.suggested_filename
        assert re.fullmatch(name, download.suggested_filename), (format, download.suggested_filename)
        assert body and valid(body), (format, body[:200])
    # The hint says what an export holds.
    expect(page.locator("#download-settings")).to_contain_text("ηᵢ 1.33, roughness 0.35, coat roughness 0.10")
    assert len(set(got.values())) == len(FORMATS), got


def test_saving_again_continues_the_saved_material(pages, editor_url):
    page = pages.new()
    dialogs = []
    page.on("dialog", lambda dialog: (dialogs.append(dialog.message), dialog.dismiss()))
    open_editor(page, editor_url)
    settled(page)
    key_edit(page)
    page.fill("#name", "Continued gold")
    page.click("#save")
    expect(page.locator("#message")).to_contain_text("Saved “Continued gold”")
    key_edit(page, channel=0, angle=60, key="Shift+ArrowDown")
    page.click("#save")
    expect(page.locator("#message")).to_contain_text("version 2")
    material = page.evaluate("fetch('/api/v1/materials').then(r => r.json()).then(j => j.materials"
                             ".find(m => m.name === 'Continued gold'))")
    assert material["version"] == 2
    # Opened from the list, a save continues it too.
    page.select_option("#material", f"saved:{material['id']}")
    settled(page)
    expect(page.locator("#name")).to_have_value("Continued gold")
    key_edit(page, channel=2, angle=20, key="Shift+ArrowUp")
    page.click("#save")
    expect(page.locator("#message")).to_contain_text("version 3")
    versions = page.evaluate(f"fetch('/api/v1/materials/{material['id']}/versions').then(r => r.json())")
    assert [v["version"] for v in versions["versions"]] == [3, 2, 1]
    assert dialogs == []  # never "Replace it?" for the material one saved or opened
