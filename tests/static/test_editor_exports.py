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


PACKS = {"binary", "json", "glsl", "hlsl"}


def set_range(page, selector, value):
    page.eval_on_selector(
        selector, "(el, v) => { el.value = v; el.dispatchEvent(new Event('input', {bubbles: true})); }", str(value)
    )


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
    "glb": (EXPORT_STEM + r"\.glb", lambda b: b[:4] == b"glTF"),  # the binary glTF header's magic
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
    # The menu's exports are the service's (GET /domain), glb among them.
    page.wait_for_function("document.querySelectorAll('#export-formats option').length > 0")
    menu = page.eval_on_selector_all("#export-formats option", "options => options.map(o => o.value)")
    domain = page.evaluate("fetch('/api/v1/domain').then(r => r.json())")
    assert menu == [f["name"] for f in domain["export_formats"]] and set(menu) == set(FORMATS) - PACKS, menu
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


def download(page, format):
    """The fit on screen downloaded in `format`: a file for set_input_files, under its own name."""
    page.select_option("#format", format)
    with page.expect_download() as info:
        page.click("#download")
    got = info.value
    return {
        "name": got.suggested_filename,
        "mimeType": "application/octet-stream",
        "buffer": open(got.path(), "rb").read(),
    }


def open_file(page, file):
    """Open `file` with "Open a pack or export"; the message the page says once the fit on screen is settled."""
    page.evaluate("document.getElementById('open-message').textContent = ''")
    page.set_input_files("#open-file", file)
    page.wait_for_function("document.getElementById('open-message').textContent !== ''")
    settled(page)
    return page.inner_text("#open-message")


def test_open_file_opens_a_pack_or_an_export(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    edited = key_edit(page)
    files = {format: download(page, format) for format in ("json", "glb", "binary")}
    page = pages.new()  # a fresh page: gold, no edits
    open_editor(page, editor_url)
    settled(page)
    # The JSON pack and the export name the fit: it opens with its edit.
    for format in ("json", "glb"):
        said = open_file(page, files[format])
        assert said == f"Opened “Au edited” from {files[format]['name']}.", said
        assert page.inner_text("#fit-id") == edited, format
        assert page.locator("#edited-etas button").all_inner_texts() == ["1.50"], format
    # The binary pack holds the model alone: a fit of that model opens, as a base of its own. It
    # has nothing it was fitted to, so its error map is refused (422) and the heat map says so.
    pages.expected.append("422")  # that refusal's console line, and the damaged file's below
    said = open_file(page, files["binary"])
    assert said.startswith("Opened") and page.inner_text("#fit-id") != edited, said
    expect(page.locator("#heatmap-caption")).to_contain_text("Error map unavailable")
    opened = page.inner_text("#fit-id")
    # A damaged file: refused with the service's reason, nothing changes.
    said = open_file(page, {"name": "broken.glb", "mimeType": "model/gltf-binary", "buffer": b"glTF broken"})
    assert said.startswith("Not opened:") and page.inner_text("#fit-id") == opened, said


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
    material = page.evaluate(
        "fetch('/api/v1/materials').then(r => r.json()).then(j => j.materials.find(m => m.name === 'Continued gold'))"
    )
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
