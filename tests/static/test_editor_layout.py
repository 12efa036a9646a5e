"""
The editor's layout in a real Chromium against a real server (
"a layout for every window"): at 1280, 880, 800 and 390 px wide a dragged
point stays under the pointer from the first move of the first edit on
(nothing above the plot changes height: "No edits yet." becoming the row
of edited eta_i once took 20 px at <= 880 px, and the point jumped); at
800 x 600 the plot and the preview are in view together; on a 390 x 844
phone the handles are touch-sized and the axis text readable.
"""

from __future__ import annotations

import pytest
from editor_pages import editor_url, open_editor, pages, chromium, live_server  # noqa: F401 (fixtures: one server and one Chromium a module)

pytestmark = [pytest.mark.server, pytest.mark.browser]

HEIGHTS = {1280: 720, 880: 800, 800: 600, 390: 844}
# The pointer and the handle's centre agree to a pixel: the value is the
# pointer's (plot.value of its SVG y), drawn back at y(value); the rest is
# rounding of the bounding box to device pixels.
PIXEL = 1.0


def centre(page, selector):
    box = page.locator(selector).bounding_box()
    return box["x"] + box["width"] / 2, box["y"] + box["height"] / 2


@pytest.mark.parametrize("width", [1280, 880, 800, 390])
def test_the_dragged_point_stays_under_the_pointer(pages, editor_url, width):
    page = pages.new(width, HEIGHTS[width])
    open_editor(page, editor_url)
    handle = "circle.handle.c0[data-angle='60']"
    page.locator("#plot").scroll_into_view_if_needed()
    x, y = centre(page, handle)
    plot_top = page.locator("#plot svg").bounding_box()["y"]
    before = float(page.get_attribute(handle, "aria-valuenow"))
    page.mouse.move(x, y)
    page.mouse.down()
    # The first move is the first edit: the 2 px down that sent the point up.
    trail = []
    for dy in (2, 6, 14, 24, 36):
        page.mouse.move(x, y + dy)
        page.wait_for_function(
            f"document.querySelector(\"{handle}\").getAttribute('aria-valuenow') !== '{before:.3f}'"
            if dy == 2
            else "true"
        )
        hx, hy = centre(page, handle)
        trail.append(
            (
                dy,
                hy - y,
                float(page.get_attribute(handle, "aria-valuenow")),
                page.locator("#plot svg").bounding_box()["y"] - plot_top,
            )
        )
    page.mouse.up()
    for dy, moved, _, shift in trail:
        assert shift == 0, (width, trail)  # nothing above the plot changed height
        assert abs(moved - dy) <= PIXEL, (width, trail)
    values = [before] + [value for _, _, value, _ in trail]
    assert all(b < a for a, b in zip(values, values[1:])), (width, values)  # down is darker, every move
    # The row of edited eta_i took the place of "No edits yet." without moving the plot.
    assert page.locator("#edited-etas button.chip").count() == 1


def test_plot_and_preview_in_view_together_at_800_by_600(pages, editor_url):
    page = pages.new(800, 600)
    open_editor(page, editor_url)
    plot = page.locator("#plot svg").bounding_box()
    preview = page.locator("#preview").bounding_box()
    for box in (plot, preview):
        assert box["x"] >= 0 and box["y"] >= 0, box
        assert box["x"] + box["width"] <= 800 and box["y"] + box["height"] <= 600, box
        assert box["width"] >= 240 and box["height"] >= 150, box
    assert plot["x"] + plot["width"] <= preview["x"]  # side by side


def test_phone_handles_are_touch_sized_and_axis_text_readable(pages, editor_url):
    page = pages.new(390, 844)
    open_editor(page, editor_url)
    box = page.locator("circle.handle.c0[data-angle='36']").bounding_box()
    assert box["width"] >= 24 and box["height"] >= 24, box
    sizes = page.evaluate("""() => {
        const svg = document.querySelector('#plot svg');
        const scale = svg.getScreenCTM().a;
        return Array.from(svg.querySelectorAll('.axis text'), (t) => parseFloat(getComputedStyle(t).fontSize) * scale);
    }""")
    assert sizes and min(sizes) >= 11, sizes
    # Nothing wider than the phone (no sideways scrolling).
    assert page.evaluate("document.documentElement.scrollWidth") <= 390


@pytest.mark.parametrize("width, height", [(1920, 1080), (1280, 800)])
def test_the_preview_takes_45_percent_and_save_stays_in_view(pages, editor_url, width, height):
    page = pages.new(width, height)
    open_editor(page, editor_url)
    preview = page.locator("#preview").bounding_box()
    assert preview["width"] >= 0.45 * width, preview
    assert preview["y"] + preview["height"] <= height, preview  # the whole ball on the first screen
    assert page.evaluate("document.documentElement.scrollWidth") <= width  # nothing cut off at the side
    for selector in ("#plot svg", ".controls", ".side"):
        box = page.locator(selector).bounding_box()
        assert box["x"] >= 0 and box["x"] + box["width"] <= width, (selector, box)
    # Save is on the first screen, not covered by anything.
    save = page.locator("#save").bounding_box()
    assert 0 <= save["y"] and save["y"] + save["height"] <= height, save
    hit = page.evaluate(
        "([x, y]) => document.elementFromPoint(x, y).id",
        [save["x"] + save["width"] / 2, save["y"] + save["height"] / 2],
    )
    assert hit == "save"
