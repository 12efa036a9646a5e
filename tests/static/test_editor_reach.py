"""
Edits beyond the model's reach, in a real Chromium against a real server:
pulling a point to 0 shows a plain warning with the largest miss and where,
the fit stays within [0, 1] over its whole domain, and "Make the edit
gentler" moves the edit halfway back (undoable). "All three" scales the
three channels instead of adding an offset.
"""

from __future__ import annotations

import numpy as np
import pytest
from editor_pages import editor_url, open_editor, pages, chromium, live_server, settled  # noqa: F401 (fixtures: one server and one Chromium a module)
from playwright.sync_api import expect

pytestmark = [pytest.mark.server, pytest.mark.browser]


def value(page, channel, angle):
    return float(page.get_attribute(f"circle.handle.c{channel}[data-angle='{angle}']", "aria-valuenow"))


def model_range(page, fit_id):
    low, high = np.inf, -np.inf
    for eta in np.linspace(1.0, 2.5, 7):
        curves = page.evaluate(f"fetch('/api/v1/fits/{fit_id}/curves?eta_i={eta:.3f}&samples=181').then(r => r.json())")
        model = np.asarray(curves["model"])
        low, high = min(low, model.min()), max(high, model.max())
    return low, high


def test_extreme_edit_warns_stays_in_range_and_can_be_gentler(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    base_id = settled(page)
    assert page.is_hidden("#reach")
    page.locator("circle.handle.c0[data-angle='60']").focus()
    for _ in range(5):
        page.keyboard.press("Shift+PageDown")
    assert value(page, 0, 60) == 0.0
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{base_id}'")
    extreme_id = settled(page)
    expect(page.locator("#reach")).to_be_visible()
    text = page.inner_text("#reach-text")
    assert "cannot follow" in text and "ΔE" in text and "°" in text and "ηᵢ" in text
    # Each edited curve the fit cannot follow, in the server's words (where and by how much).
    said = page.evaluate(f"fetch('/api/v1/fits/{extreme_id}').then(r => r.json())")["metrics"]["details"]["warnings"]
    assert said and all("edit not followed" in w for w in said)
    assert page.locator("#reach-warnings li").all_inner_texts() == said
    low, high = model_range(page, extreme_id)
    assert low >= -2e-4 and high <= 1.0 + 2e-4, (low, high)

    page.click("#reach-gentler")
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{extreme_id}'")
    settled(page)
    reference = 0.5 * value(page, 0, 60)
    assert 0.2 < value(page, 0, 60) < 0.6 and reference > 0  # Au's red at 60 degrees: a sanity range
    page.click("#undo")
    page.wait_for_function(f"document.getElementById('fit-id').textContent === '{extreme_id}'")
    assert value(page, 0, 60) == 0.0


def test_all_three_scales_the_channels(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    base_id = settled(page)
    before = [value(page, c, 36) for c in range(3)]
    page.locator("input[name=channel][value='all']").check()
    page.locator("circle.handle.c0[data-angle='36']").focus()
    page.keyboard.press("Shift+PageDown")  # red -0.25
    after = [value(page, c, 36) for c in range(3)]
    ratios = [a / b for a, b in zip(after, before)]
    # Derived from the handles' aria-valuenow, printed with 3 decimals
    # (static/plot.js toFixed(3)): each value within 5e-4, so a ratio a / b
    # within 5e-4 (1 + a / b) / b: 2e-3 for red (b ~ 0.5), 3e-3 and 6e-3 for
    # the darker green and blue (b down to ~0.17).
    assert ratios[0] == pytest.approx((before[0] - 0.25) / before[0], abs=2e-3)
    # The same factor on every channel (hue kept), not the same offset.
    assert ratios[1] == pytest.approx(ratios[0], abs=3e-3) and ratios[2] == pytest.approx(ratios[0], abs=6e-3)
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{base_id}'")
    settled(page)
