"""
The materials an artist manages, in a real Chromium against a real server:
the saved list holds saved edits only (an upload is under
Uploads in the picker, drafts nowhere); rename; delete to the bin and
restore (Undo, or from the bin), with the API token when the service wants
one; the versions of a material (an older one opened with its edit,
downloaded, saved again as the next version); the link that reopens a fit
with its edit (`?fit=`) and the service's `?material=&version=` link.
"""

from __future__ import annotations

import json
import re

import pytest
from conftest import server_process
from editor_pages import editor_url, key_edit, open_editor, pages, chromium, live_server, settled  # noqa: F401 (fixtures: one server and one Chromium a module)
from playwright.sync_api import expect

pytestmark = [pytest.mark.server, pytest.mark.browser]

NK = {
    "wavelength_nm": [350, 450, 550, 650, 750, 850],
    "n": [1.5, 1.4, 0.4, 0.2, 0.15, 0.2],
    "k": [1.9, 1.9, 2.4, 3.6, 4.6, 5.6],
}


def api(page, path, method="GET", body=None):
    init = (
        f"{{method: '{method}', headers: {{'Content-Type': 'application/json'}}, body: JSON.stringify({body!r})}}"
        if body is not None
        else f"{{method: '{method}'}}"
    )
    return page.evaluate(f"fetch('/api/v1{path}', {init}).then(r => r.json())")


def save_as(page, name, version_text=None):
    page.fill("#name", name)
    page.click("#save")
    expect(page.locator("#message")).to_contain_text(version_text or f"Saved “{name}”")
    return settled(page)


def saved_item(page, material_id):
    return page.locator(f"#saved-list li[data-id='{material_id}']")


def test_saved_list_rename_delete_restore(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    api(page, "/fits", "POST", {"name": "Upload apart", "nk": NK})  # an upload: kind nk
    key_edit(page)
    fit = save_as(page, "Managed gold")
    material = api(page, f"/fits/{fit}")["material_id"]
    item = saved_item(page, material)
    expect(item.locator(".title")).to_have_text("Managed gold")
    expect(page.locator("#saved-list")).not_to_contain_text("Upload apart")
    page.reload()
    page.wait_for_selector("body[data-ready=true]")
    expect(page.locator("#material optgroup[label='Uploads (n, k)'] option")).to_contain_text(["Upload apart (n, k)"])
    expect(page.locator("#material optgroup[label='Saved'] option")).to_contain_text(["Managed gold (edited)"])
    expect(page.locator("#saved-list")).not_to_contain_text("Upload apart")

    # Rename in place: Escape keeps the old name, Enter the new one.
    item.get_by_role("button", name="Rename Managed gold").click()
    page.keyboard.type("Not this")
    page.keyboard.press("Escape")
    expect(item.locator(".title")).to_have_text("Managed gold")
    item.get_by_role("button", name="Rename Managed gold").click()
    field = item.get_by_role("textbox")
    field.fill("Renamed gold")
    field.press("Enter")
    expect(item.locator(".title")).to_have_text("Renamed gold")
    expect(page.locator("#manage-message")).to_contain_text("Renamed “Managed gold” to “Renamed gold”")
    assert api(page, f"/materials/{material}")["name"] == "Renamed gold"
    expect(page.locator(f"#material option[value='saved:{material}']")).to_have_text("Renamed gold (edited)")

    # Delete: to the bin; Undo brings it back.
    item.get_by_role("button", name="Delete Renamed gold (to the bin)").click()
    expect(item).to_have_count(0)
    expect(page.locator("#bin-count")).to_have_text("1")
    assert api(page, f"/materials/{material}")["deleted_at"] is not None
    expect(page.locator(f"#material option[value='saved:{material}']")).to_have_count(0)
    page.locator("#manage-message button", has_text="Undo").click()
    expect(item.locator(".title")).to_have_text("Renamed gold")
    expect(page.locator("#bin-count")).to_have_text("0")
    assert api(page, f"/materials/{material}")["deleted_at"] is None
    # ... and Restore from the bin.
    item.get_by_role("button", name="Delete Renamed gold (to the bin)").click()
    expect(item).to_have_count(0)
    expect(page.locator("#bin-count")).to_have_text("1")
    page.click("#bin summary")
    page.locator(f"#bin-list li[data-id='{material}']").get_by_role("button", name="Restore Renamed gold").click()
    expect(item.locator(".title")).to_have_text("Renamed gold")
    expect(page.locator("#bin-list li")).to_have_count(0)


def test_delete_sends_the_write_token(pages, tmp_path):
    token = "manage-browser-test-token"
    with server_process(tmp_path / "data", COATED_REQUIRE_TOKEN="true", COATED_API_TOKEN=token) as server:
        page = pages.new()
        pages.expected.append("status of 401")  # the refused delete, on purpose
        page.add_init_script(f"sessionStorage.setItem('coated-api-token', '{token}')")
        writes = []
        page.on("request", lambda r: writes.append(r) if r.method == "DELETE" else None)
        open_editor(page, server.url + "/")
        settled(page)
        key_edit(page)
        fit = save_as(page, "Token gold")
        material = api(page, f"/fits/{fit}")["material_id"]
        # Without the token the delete is refused (401) and the token field opens; with it, the delete is retried.
        page.click("#token-settings summary")
        page.fill("#token", "")
        page.press("#token", "Enter")
        expect(page.locator("#message")).to_have_text("API token cleared.")
        saved_item(page, material).get_by_role("button", name="Delete Token gold (to the bin)").click()
        expect(page.locator("#message")).to_contain_text("Not deleted: The service needs its API token (401)")
        expect(page.locator("#token")).to_be_focused()
        assert api(page, f"/materials/{material}")["deleted_at"] is None
        page.fill("#token", token)
        page.press("#token", "Enter")
        expect(page.locator("#bin-count")).to_have_text("1")
        assert writes[-1].headers.get("authorization") == f"Bearer {token}"
        assert api(page, f"/materials/{material}")["deleted_at"] is not None
        page.close()


def test_versions_open_download_and_continue(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    key_edit(page, channel=1, angle=36, key="Shift+ArrowUp")
    first = save_as(page, "Versioned gold")
    green = page.get_attribute("circle.handle.c1[data-angle='36']", "aria-valuenow")
    key_edit(page, channel=0, angle=60, key="Shift+ArrowDown")
    red_first = api(page, f"/fits/{first}/edit")["request"]["curves"][0]["rgb"][30][0]  # 60 degrees
    second = save_as(page, "Versioned gold", "version 2")
    material = api(page, f"/fits/{second}")["material_id"]
    saved_item(page, material).get_by_role("button", name="Versions of Versioned gold").click()
    expect(page.locator("#versions-heading")).to_have_text("Versions of “Versioned gold”")
    rows = page.locator("#versions-list li")
    expect(rows).to_have_count(2)
    assert rows.evaluate_all("els => els.map(e => e.dataset.version)") == ["2", "1"]
    # Each version's figures: the mean and the worst point.
    for row in api(page, f"/materials/{material}/versions")["versions"]:
        expect(page.locator(f"#versions-list li[data-version='{row['version']}']")).to_contain_text(
            f"ΔE₀₀ {row['delta_E_mean']:.2f}, max {row['delta_E_max']:.2f}"
        )
    # Any version downloads, in the Download menu's format as it is at the click (the list is not
    # listed again), an export at the preview's settings, as the fit's own Download.
    download_v1 = page.locator("#versions-list li[data-version='1']").get_by_role("link", name="Download version 1")
    page.select_option("#format", "json")
    with page.expect_download() as info:
        download_v1.click()
    assert info.value.suggested_filename.endswith(".json") and first[:8] in info.value.suggested_filename
    page.eval_on_selector(
        "#roughness", "el => { el.value = '0.35'; el.dispatchEvent(new Event('input', {bubbles: true})); }"
    )
    page.select_option("#format", "mtlx")
    with page.expect_download() as info:
        download_v1.click()
    assert re.fullmatch(rf".*-{first[:8]}-eta1\.5-rough0\.35-coat[0-9.]+\.mtlx", info.value.suggested_filename), (
        info.value.suggested_filename
    )
    # An older version opens with its edit: its fit, its edited points, the material it belongs to.
    page.locator("#versions-list li[data-version='1']").get_by_role("button", name="Open version 1").click()
    expect(page.locator("#fit-id")).to_have_text(first)
    settled(page)
    expect(page.locator("circle.handle.c1[data-angle='36']")).to_have_attribute("aria-valuenow", green)
    expect(page.locator("circle.handle.c0[data-angle='60']")).to_have_attribute("aria-valuenow", f"{red_first:.3f}")
    expect(page.locator("#name")).to_have_value("Versioned gold")
    expect(page.locator("#edited-etas")).to_contain_text("1.50")
    expect(page.locator("#save-state")).to_have_text("Saved")
    # Two saved versions compared: version 2 beside version 1 on screen.
    page.locator("#versions-list li[data-version='2']").get_by_role("button", name="Compare version 2").click()
    expect(page.locator("#preview-compare")).to_have_attribute("data-fit", second)
    expect(page.locator("#compare-de")).to_have_attribute("data-fit", second)
    assert float(page.inner_text("#compare-de")) > 0
    expect(page.locator("#compare-caption")).to_contain_text(f"right: version 2 ({second[:8]})")
    page.click("#compare-off")
    # Saved again, it is the next version of the same material.
    key_edit(page, channel=2, angle=20, key="Shift+ArrowUp")
    save_as(page, "Versioned gold", "version 3")
    assert api(page, f"/materials/{material}/versions")["version"] == 3


def test_link_reopens_the_material_with_its_edit(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    key_edit(page, channel=2, angle=50, key="Shift+ArrowDown")
    fit = save_as(page, "Linked gold")
    blue = page.get_attribute("circle.handle.c2[data-angle='50']", "aria-valuenow")
    material = api(page, f"/fits/{fit}")["material_id"]
    saved_item(page, material).get_by_role("button", name="Copy the link to Linked gold").click()
    link = page.input_value("#share-link")
    assert link == f"{editor_url}?fit={fit}"
    expect(page.locator("#manage-message")).to_contain_text(link)

    other = pages.new()
    open_editor(other, link)
    expect(other.locator("#fit-id")).to_have_text(fit)
    settled(other)
    expect(other.locator("#name")).to_have_value("Linked gold")
    expect(other.locator("#material")).to_have_value(f"saved:{material}")
    expect(other.locator("circle.handle.c2[data-angle='50']")).to_have_attribute("aria-valuenow", blue)
    expect(other.locator("#edited-etas")).to_contain_text("1.50")
    expect(other.locator("#save-state")).to_have_text("Saved")
    assert other.get_attribute("body", "data-unsaved") == "false"
    key_edit(other, channel=0, angle=20, key="Shift+ArrowUp")
    save_as(other, "Linked gold", "version 2")
    # The service's share_url form opens a version.
    version_link = f"{editor_url}?material={material}&version=1"
    open_editor(other, version_link)
    expect(other.locator("#fit-id")).to_have_text(fit)


def test_a_save_puts_its_own_fit_on_screen(pages, editor_url):
    """
    The fit on screen before a save can be a draft of the same edits under the name as it was (a
    refit in flight when the name was changed): the draft refits are made to carry the old name
    here, on the way to the server. The save's own fit then replaces it on screen: what is shown
    and downloaded is the saved material's latest fit, and the page does not call it unsaved.
    """
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    draft = key_edit(page, channel=0, angle=60, key="Shift+ArrowDown")
    old_name = page.input_value("#name")

    def under_the_old_name(route):
        body = route.request.post_data_json
        if body and body.get("draft"):
            route.continue_(post_data=json.dumps({**body, "name": old_name}))
        else:
            route.continue_()

    page.route("**/fits/from-curves**", under_the_old_name)
    try:
        shown = save_as(page, "Saved under its own name")
    finally:
        page.unroute("**/fits/from-curves**")
    saved = api(page, f"/fits/{shown}")
    assert shown != draft and saved["name"] == "Saved under its own name"
    assert api(page, f"/materials/{saved['material_id']}")["latest_fit"]["id"] == shown
    expect(page.locator("body")).to_have_attribute("data-unsaved", "false")
