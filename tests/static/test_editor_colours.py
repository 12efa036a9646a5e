"""
The colour controls in a real Chromium against a real server: typing a base
colour and an edge tint (sRGB hex) sets the curves to that metal and the
refit follows it (the fit's colour at normal incidence in air within 1 Delta
E 2000 of the picked one, its curves moved from gold's), one undo step
back; under the coat the colour is the plot's curve at 0 degrees; a
colour the model cannot follow shows the reach warning with the server's
words; the falloff control: none moves the dragged point alone, wide moves
its neighbours too.
"""

from __future__ import annotations

import numpy as np
import pytest
from editor_pages import editor_url, open_editor, pages, chromium, live_server, settled  # noqa: F401 (fixtures)
from playwright.sync_api import expect

from benchmarks.colour_controls import srgb_hex_to_linear
from fitting.colour.delta_e import delta_E_map
from fitting.exports.colour_space import lin_rec709_to_ACEScg

pytestmark = [pytest.mark.server, pytest.mark.browser]


def curves(page, fit_id, eta):
    return page.evaluate(f"fetch('/api/v1/fits/{fit_id}/curves?eta_i={eta:.3f}&samples=46').then(r => r.json())")


def pick(page, field, hex_colour):
    page.fill(f"#{field}", hex_colour)
    page.press(f"#{field}", "Enter")


def refitted(page, before):
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{before}'")
    return settled(page)


def handle(page, channel, angle):
    return float(page.get_attribute(f"circle.handle.c{channel}[data-angle='{angle}']", "aria-valuenow"))


def test_base_colour_and_edge_tint_move_the_fit(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    gold = settled(page)
    shown = page.input_value("#base-hex")
    assert shown.startswith("#") and len(shown) == 7, "the pickers show the material's colours"
    gold_air = np.asarray(curves(page, gold, 1.0)["model"])
    base, edge = "#c4d0e8", "#e0ecff"  # a cool steel: far from gold
    pick(page, "edge-hex", edge)
    fit_id = refitted(page, gold)
    pick(page, "base-hex", base)
    fit_id = refitted(page, fit_id)
    assert page.input_value("#base-colour") == base and page.input_value("#edge-colour") == edge
    expect(page.locator("#colour-message")).to_contain_text("Curves set to the metal of these colours in air")
    fitted_air = np.asarray(curves(page, fit_id, 1.0)["model"])
    picked = lin_rec709_to_ACEScg(srgb_hex_to_linear(base))
    assert delta_E_map(picked, fitted_air[0]) < 1.0
    assert delta_E_map(picked, gold_air[0]) > 10.0, "gold is far from the picked colour"
    assert np.abs(fitted_air[:40] - gold_air[:40]).max() > 0.2, "the curves moved"
    chips = page.locator("#edited-etas button").all_inner_texts()
    assert chips == ["1.00", "1.50", "2.00", "2.50"], chips  # every 0.5 of the domain: the whole metal
    page.click("#undo")  # the base colour was one edit
    refitted(page, fit_id)

    # Under the coat: the picked colour is the plot's curve at 0 degrees at the slider's eta_i (1.5).
    page.check("input[name=colour-at][value=coat]")
    before = settled(page)
    pick(page, "base-hex", base)
    coated = refitted(page, before)
    at_coat = np.asarray(curves(page, coated, 1.5)["model"])
    assert delta_E_map(picked, at_coat[0]) < 1.0


def test_a_colour_the_model_cannot_follow_says_where(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    before = settled(page)
    assert page.is_hidden("#reach")
    pick(page, "edge-hex", "#0000ff")  # a deep blue edge on gold: out of any conductor's reach in red
    fit_id = refitted(page, before)
    expect(page.locator("#colour-message")).to_contain_text("No metal reaches this edge tint")
    expect(page.locator("#reach")).to_be_visible()
    assert "cannot follow" in page.inner_text("#reach-text")
    said = page.evaluate(f"fetch('/api/v1/fits/{fit_id}').then(r => r.json())")["metrics"]["details"]["warnings"]
    assert page.locator("#reach-warnings li").all_inner_texts() == said


def test_falloff_none_moves_the_point_alone(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    settled(page)
    neighbours = [handle(page, 0, 50), handle(page, 0, 70)]
    page.locator("circle.handle.c0[data-angle='60']").focus()
    page.keyboard.press("Shift+ArrowUp")
    assert [handle(page, 0, 50), handle(page, 0, 70)] == neighbours
    page.select_option("#falloff", "wide")
    page.locator("circle.handle.c0[data-angle='60']").focus()
    page.keyboard.press("Shift+ArrowUp")
    assert handle(page, 0, 50) > neighbours[0] and handle(page, 0, 70) > neighbours[1]
    settled(page)
