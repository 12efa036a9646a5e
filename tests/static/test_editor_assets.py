"""
The asset model of the editor, in a real Chromium against a real server:
a refit is a draft (not listed under Saved), the page knows it has unsaved
changes and asks before switching material, Save stores under the name and
asks before replacing another saved material, a reload returns to the
material open last, and the layout at 1024 x 700 keeps the plot and the
preview in view together.
"""

from __future__ import annotations

import pytest
from editor_pages import editor_url, open_editor, pages, chromium, live_server, settled  # noqa: F401 (fixtures: one server and one Chromium a module)
from playwright.sync_api import expect

pytestmark = [pytest.mark.server, pytest.mark.browser]


def key_edit(page, channel=1, angle=36, key="Shift+ArrowUp"):
    page.locator(f"input[name=channel][value='{channel}']").check()
    page.locator(f"circle.handle.c{channel}[data-angle='{angle}']").focus()
    page.keyboard.press(key)


def saved_names(page, other=()):
    """Names of the saved curve materials, but ``other`` (what other modules on the shared server saved)."""
    names = page.evaluate(
        "fetch('/api/v1/materials').then(r => r.json())"
        ".then(j => j.materials.filter(m => m.kind === 'curves').map(m => m.name))"
    )
    return [name for name in names if name not in other]


def test_drafts_save_replace_and_reload(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    base_id = settled(page)
    other = set(saved_names(page))  # the browser modules share one server
    key_edit(page)
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{base_id}'")
    settled(page)
    # A refit is a draft: nothing is listed under Saved, the page says so.
    assert saved_names(page, other) == []
    expect(page.locator("#save-state")).to_contain_text("Unsaved")
    assert page.get_attribute("body", "data-unsaved") == "true"

    # Switching material asks first; declining keeps the edit.
    dialogs = []

    def decline(dialog):
        dialogs.append(dialog.message)
        dialog.dismiss()

    page.once("dialog", decline)
    page.select_option("#material", "library:Cu")
    page.wait_for_timeout(300)
    assert dialogs and "unsaved" in dialogs[0].lower()
    expect(page.locator("#material")).to_have_value("library:Au")
    assert page.get_attribute("body", "data-unsaved") == "true"

    # Save stores it under its name.
    page.fill("#name", "Asset test gold")
    page.click("#save")
    expect(page.locator("#message")).to_contain_text("Saved “Asset test gold”")
    assert saved_names(page, other) == ["Asset test gold"]
    expect(page.locator("#save-state")).to_have_text("Saved")
    saved_value = page.input_value("#material")
    assert saved_value.startswith("saved:")

    # A reload returns to the material open last (the saved edit).
    open_editor(page, editor_url)
    expect(page.locator("#material")).to_have_value(saved_value)
    assert page.get_attribute("body", "data-unsaved") == "false"

    # Another material saved under the same name: asked first; declining saves nothing.
    page.select_option("#material", "library:Cu")
    page.wait_for_function("document.getElementById('name').value === 'Cu edited'")
    settled(page)
    cu_base = page.inner_text("#fit-id")
    key_edit(page, 0, 50, "Shift+ArrowDown")
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{cu_base}'")
    settled(page)
    page.fill("#name", "Asset test gold")
    page.once("dialog", decline)
    page.click("#save")
    expect(page.locator("#message")).to_contain_text("Not saved")
    assert "Replace" in dialogs[-1]
    gold = page.evaluate(
        "fetch('/api/v1/materials').then(r => r.json()).then(j => j.materials.find(m => m.name === 'Asset test gold'))"
    )
    assert "Au" in gold["source"]
    # Accepting replaces it.
    page.once("dialog", lambda dialog: dialog.accept())
    page.click("#save")
    expect(page.locator("#message")).to_contain_text("Saved “Asset test gold”")
    gold = page.evaluate(
        "fetch('/api/v1/materials').then(r => r.json()).then(j => j.materials.find(m => m.name === 'Asset test gold'))"
    )
    assert "Cu" in gold["source"]
    assert saved_names(page, other) == ["Asset test gold"]


def test_layout_at_1024_by_700_keeps_plot_and_preview_in_view(pages, editor_url):
    page = pages.new(1024, 700)
    open_editor(page, editor_url)
    settled(page)
    plot = page.locator("#plot svg").bounding_box()
    preview = page.locator("#preview").bounding_box()
    for box in (plot, preview):
        assert box["x"] >= 0 and box["y"] >= 0
        assert box["x"] + box["width"] <= 1024 and box["y"] + box["height"] <= 700, box
        assert box["width"] >= 240 and box["height"] >= 150, box
    # Side by side, not overlapping.
    assert plot["x"] + plot["width"] <= preview["x"]
    # The upload message sits next to the upload control.
    upload = page.locator("#upload").bounding_box()
    message = page.locator("#upload-message").bounding_box()
    assert 0 <= message["y"] - (upload["y"] + upload["height"]) < 30
