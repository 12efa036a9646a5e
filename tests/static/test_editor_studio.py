"""
The editor an artist keeps open all day, in a real Chromium
against a real server: the library to browse (search by name, symbol or
source; swatches at the current eta_i; open a metal from it), the coat
presets and typed entry (eta_i and the selected point's value, checked,
refitted as a drag), compare mode (a fit and its edit, two metals: the
second ball, the overlaid curves, the Delta E 2000 computed in the page
against the Python scoring of the same curves), and the polish: a burst of
key presses is one undo step, the heat map never shows the previous fit's
map, the upload's coverage rule is on screen.
"""

from __future__ import annotations

import numpy as np
import pytest
from editor_pages import editor_url, key_edit, open_editor, pages, chromium, live_server, settled  # noqa: F401 (fixtures: one server and one Chromium a module)
from playwright.sync_api import expect

from fitting.colour.delta_e import delta_E_map
from fitting.optics.catalogue import catalogue

pytestmark = [pytest.mark.server, pytest.mark.browser]


def api(page, path):
    return page.evaluate(f"fetch('/api/v1{path}').then(r => r.json())")


def test_library_search_swatches_and_open(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    items = page.locator("#library-list li")
    expect(items).to_have_count(len(catalogue()))
    gold = page.locator("#library-list li[data-id='Au']")
    expect(gold.locator(".title")).to_have_text("gold (Au)")
    expect(gold.locator(".meta")).to_contain_text("metal · Johnson and Christy 1972")
    expect(gold.locator(".meta")).to_contain_text("nm")
    library = api(page, "/library?eta_i=1.50")
    au = next(m for m in library["materials"] if m["id"] == "Au")
    expect(gold.locator(".chip-swatch")).to_have_attribute("data-srgb", au["swatch"]["srgb"][0])
    # Search by name, symbol or another name: the service's ?q= answer, in its order.
    for query in ["gold", "Cu", "titanium", "aluminum", "stainless"]:
        page.fill("#library-search", query)
        expect(page.locator("#library-state")).to_contain_text(f"match “{query}”")
        ids = page.eval_on_selector_all("#library-list li", "els => els.map(e => e.dataset.id)")
        served = [m["id"] for m in api(page, f"/library?eta_i=1.5&q={query.replace(' ', '+')}")["materials"]]
        assert ids == served and ids, (query, ids, served)
        assert ids[0] == {"gold": "Au", "Cu": "Cu", "aluminum": "Al"}.get(query, ids[0])
    assert catalogue()[ids[0]]["book"] == "stainless_steel"
    # A search that matches nothing lists what the service suggests instead, and says so.
    page.fill("#library-search", "stainless steel 316")
    expect(page.locator("#library-state")).to_contain_text("No conductor matches “stainless steel 316”; did you mean")
    suggested = [m["id"] for m in api(page, "/library?eta_i=1.5&q=stainless+steel+316")["suggestions"]]
    ids = page.eval_on_selector_all("#library-list li", "els => els.map(e => e.dataset.id)")
    assert ids == suggested and len(ids) == 2, (ids, suggested)
    page.fill("#library-search", "")
    # The swatches follow eta_i.
    page.fill("#eta-typed", "1.00")
    page.press("#eta-typed", "Enter")
    expect(page.locator("#library-list")).to_have_attribute("data-eta", "1.00")
    au_air = next(m for m in api(page, "/library?eta_i=1.00")["materials"] if m["id"] == "Au")
    expect(gold.locator(".chip-swatch")).to_have_attribute("data-srgb", au_air["swatch"]["srgb"][0])
    assert au_air["swatch"]["srgb"] != au["swatch"]["srgb"]
    # Picking one opens it.
    page.locator("#library-list li[data-id='Cu'] button", has_text="Open").click()
    expect(page.locator("#material")).to_have_value("library:Cu")
    settled(page)
    expect(page.locator("#name")).to_have_value("Cu edited")
    expect(page.locator("#library-list li[data-id='Cu']")).to_have_class("current")


def test_presets_and_typed_entry(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    presets = api(page, "/coat-presets")["presets"]
    buttons = page.eval_on_selector_all(
        "#coat-presets button", "els => els.map(e => [e.dataset.id, e.title, e.textContent])"
    )
    shown = [
        f"{p['name']} {p['eta_i']:.1f}" if float(p["eta_i"]).is_integer() else f"{p['name']} {p['eta_i']:g}"
        for p in presets
    ]
    assert buttons == [[p["id"], p["source"], text] for p, text in zip(presets, shown)]
    page.click("#coat-presets button[data-id='water']")
    expect(page.locator("#eta-value")).to_have_text("1.33")
    expect(page.locator("#plot")).to_have_attribute("data-eta", "1.33")
    expect(page.locator("#preview")).to_have_attribute("data-eta", "1.33")
    expect(page.locator("#entry-message")).to_contain_text("Coat: Water")
    expect(page.locator("#coat-presets button[data-id='water']")).to_have_attribute("aria-pressed", "true")
    # eta_i typed: checked against the material's domain, nothing changes when refused.
    page.fill("#eta-typed", "2.7")
    page.press("#eta-typed", "Enter")
    expect(page.locator("#entry-message")).to_have_text("ηᵢ (the material's domain) must lie in [1, 2.5], got 2.7.")
    expect(page.locator("#eta-typed")).to_have_attribute("aria-invalid", "true")
    expect(page.locator("#eta-value")).to_have_text("1.33")
    page.fill("#eta-typed", "1.8")
    page.press("#eta-typed", "Enter")
    expect(page.locator("#plot")).to_have_attribute("data-eta", "1.80")
    expect(page.locator("#coat-presets button[aria-pressed=true]")).to_have_count(0)
    # Two presets share 1.5: the one pressed stays pressed.
    page.click("#coat-presets button[data-id='polyurethane']")
    expect(page.locator("#coat-presets button[aria-pressed=true]")).to_have_attribute("data-id", "polyurethane")
    expect(page.locator("#plot")).to_have_attribute("data-eta", "1.50")
    settled(page)
    # The selected point's value typed: a refit as for a drag, one undo step.
    before = page.inner_text("#fit-id")
    expect(page.locator("#point-value")).to_be_disabled()
    page.locator("input[name=channel][value='1']").check()
    page.locator("circle.handle.c1[data-angle='36']").focus()
    expect(page.locator("#point-name")).to_have_text("green at 36°")
    page.fill("#point-value", "1.2")
    page.press("#point-value", "Enter")
    expect(page.locator("#entry-message")).to_have_text("A reflectance must lie in [0, 1], got 1.2.")
    assert page.inner_text("#edited-etas") == "No edits yet."
    page.fill("#point-value", "0.9")
    page.press("#point-value", "Enter")
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{before}'")
    settled(page)
    expect(page.locator("circle.handle.c1[data-angle='36']")).to_have_attribute("aria-valuenow", "0.900")
    expect(page.locator("#edited-etas")).to_contain_text("1.50")
    expect(page.locator("#undo")).to_be_enabled()
    page.click("#undo")
    expect(page.locator("#edited-etas")).to_have_text("No edits yet.")
    expect(page.locator("#undo")).to_be_disabled()


def test_key_presses_are_one_undo_step(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    handle = page.locator("circle.handle.c0[data-angle='50']")
    start = float(handle.get_attribute("aria-valuenow"))
    handle.focus()
    for _ in range(5):
        page.keyboard.press("ArrowDown")
    expect(handle).to_have_attribute("aria-valuenow", f"{start - 0.05:.3f}")
    settled(page)
    expect(page.locator("#undo")).to_be_enabled()
    page.click("#undo")  # one step takes the whole burst back
    expect(page.locator("#edited-etas")).to_have_text("No edits yet.")
    expect(page.locator("#undo")).to_be_disabled()
    # Two bursts apart (a pause longer than a burst) are two steps.
    handle.focus()
    page.keyboard.press("ArrowUp")
    page.wait_for_timeout(1200)
    page.keyboard.press("ArrowUp")
    settled(page)
    page.locator("#name").focus()  # the point loses the focus: the burst ends
    page.click("#undo")
    expect(handle).to_have_attribute("aria-valuenow", f"{start + 0.01:.3f}")
    page.click("#undo")
    expect(page.locator("#edited-etas")).to_have_text("No edits yet.")


def test_heat_map_never_shows_the_previous_fit(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    first = settled(page)
    page.wait_for_function(f"document.getElementById('heatmap').dataset.fit === '{first}'")
    # Each time the fit on screen changes, the map then shown is none or that fit's.
    page.evaluate("""() => {
        window.seen = [];
        const record = () => window.seen.push([document.getElementById('fit-id').textContent,
                                               document.getElementById('heatmap').dataset.fit]);
        new MutationObserver(record).observe(document.getElementById('fit-id'), {childList: true, characterData: true, subtree: true});
        new MutationObserver(record).observe(document.getElementById('heatmap'), {attributes: true});
    }""")
    edited = key_edit(page, channel=2, angle=60, key="Shift+ArrowUp")
    page.wait_for_function(f"document.getElementById('heatmap').dataset.fit === '{edited}'")
    seen = page.evaluate("window.seen")
    assert seen and all(shown in ("", fit) for fit, shown in seen), seen
    expect(page.locator("#heatmap-caption")).to_contain_text("Against the")
    expect(page.locator("#upload-rule")).to_contain_text("at least 90% of 360–830 nm")


def compare_figure(page, a: str, b: str, eta: float = 1.5) -> float:
    """The mean Delta E 2000 of two fits' model curves at eta, as fitting.colour scores it."""
    curves = [api(page, f"/fits/{fit}/curves?eta_i={eta:.3f}&samples=46")["model"] for fit in (a, b)]
    return float(delta_E_map(np.asarray(curves[0]), np.asarray(curves[1])).mean())


def test_compare_a_fit_with_its_edit_and_two_metals(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    base = settled(page)
    edited = key_edit(page, channel=0, angle=50, key="PageDown")
    expect(page.locator("#compare-box")).to_be_hidden()
    page.click("#compare-base")
    expect(page.locator("#compare-box")).to_be_visible()
    expect(page.locator("#preview-compare")).to_have_attribute("data-fit", base)
    expect(page.locator("#compare-de")).to_have_attribute("data-fit", base)
    assert float(page.inner_text("#compare-de")) == pytest.approx(compare_figure(page, edited, base), abs=6e-4)
    assert page.locator("#plot path.compare").count() == 3
    expect(page.locator("#compare-state")).to_contain_text("against the base (before the edit) at ηᵢ 1.50")
    expect(page.locator("#compare-caption")).to_contain_text(f"the fit on screen ({edited[:8]})")
    # Each ball says which fit it is.
    expect(page.locator("#preview-labels")).to_have_text("The fit on screen: Model")
    expect(page.locator("#preview-compare-labels")).to_have_text("Compared: the base (before the edit): Model")
    # The second ball follows the first one's settings.
    page.check("#coat")
    page.wait_for_function("window.cfPreviewCompare && window.cfPreviewCompare.then(b => b.state.coated)")
    # Two metals: the fit on screen against copper from the library.
    page.locator("#library-list li[data-id='Cu'] button", has_text="Compare").click()
    copper = page.evaluate(
        "fetch('/api/v1/fits', {method: 'POST', headers: {'Content-Type': 'application/json'},"
        " body: JSON.stringify({material: 'Cu', eta_i_range: [1, 2.5]})}).then(r => r.json())"
    )["id"]
    expect(page.locator("#preview-compare")).to_have_attribute("data-fit", copper)
    expect(page.locator("#preview-compare-labels")).to_have_text("Compared: Cu (library): Model")
    expect(page.locator("#compare-de")).to_have_attribute("data-fit", copper)
    figure = compare_figure(page, edited, copper)
    assert figure > 5 and float(page.inner_text("#compare-de")) == pytest.approx(figure, abs=6e-4)
    # It follows eta_i.
    page.fill("#eta-typed", "2.0")
    page.press("#eta-typed", "Enter")
    expect(page.locator("#compare-state")).to_contain_text("at ηᵢ 2.00")
    page.wait_for_function("document.getElementById('plot').dataset.eta === '2.00'")
    settled(page)
    page.wait_for_function(f"""() => Math.abs(Number(document.getElementById('compare-de').textContent)
                               - {compare_figure(page, edited, copper, 2.0)}) < 6e-4""")
    page.click("#compare-off")
    expect(page.locator("#compare-box")).to_be_hidden()
    expect(page.locator("#plot path.compare")).to_have_count(0)
    expect(page.locator("#compare-readout")).to_be_hidden()


# The Split menu: its longest choice within the room for text; every preset button within the panel.
MENU_FITS = """(id) => {
    const menu = document.getElementById(id);
    const style = getComputedStyle(menu);
    const context = document.createElement('canvas').getContext('2d');
    context.font = style.font;
    const widest = Math.max(...[...menu.options].map((o) => context.measureText(o.textContent).width));
    // The room for text: the box less its padding and the arrow (20 px in Chromium).
    const room = menu.clientWidth - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight) - 20;
    const panel = menu.closest('.panel').getBoundingClientRect(), box = menu.getBoundingClientRect();
    return {widest, room, inside: box.left >= panel.left - 0.5 && box.right <= panel.right + 0.5};
}"""


@pytest.mark.parametrize("width", [1400, 1024, 880, 800, 390])
def test_split_menu_and_presets_are_never_cut_off(pages, editor_url, width):
    page = pages.new(width, 900)
    open_editor(page, editor_url)
    settled(page)
    fits = page.evaluate(MENU_FITS, "compare")
    assert fits["inside"] and fits["widest"] <= fits["room"], (width, fits)
    page.wait_for_function("document.querySelectorAll('#coat-presets button').length === 8")
    cut = page.eval_on_selector_all(
        "#coat-presets button",
        """els => els.filter((e) => {
        const panel = e.closest('.panel').getBoundingClientRect(), box = e.getBoundingClientRect();
        return e.scrollWidth > e.clientWidth || box.left < panel.left || box.right > panel.right;
    }).map((e) => e.textContent)""",
    )
    assert not cut, (width, cut)
