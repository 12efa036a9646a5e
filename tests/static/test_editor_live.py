"""
Live editing in a real Chromium against a real server: a continuous drag
refits several times while the pointer moves (one request in flight, the
latest edit sent next), and when it settles the preview shows the fit whose
id is on screen, fitted to the curves on screen; a 503 is retried with
backoff, its message shown while it lasts and cleared by the next answer.
"""

from __future__ import annotations

import json
import re

import pytest
from editor_pages import editor_url, open_editor, pages, chromium, live_server, settled  # noqa: F401 (fixtures: one server and one Chromium a module)

pytestmark = [pytest.mark.server, pytest.mark.browser]

FROM_CURVES = re.compile(r".*/api/v1/fits/from-curves(\?.*)?$")  # with or without its query


def test_continuous_drag_refits_and_ends_on_the_shown_fit(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    base_id = settled(page)
    # A first edit warms the fitting worker (its base grid of the material).
    page.locator("circle.handle.c2[data-angle='20']").focus()
    page.locator("input[name=channel][value='2']").check()
    page.locator("circle.handle.c2[data-angle='20']").focus()
    page.keyboard.press("ArrowUp")
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{base_id}'")
    page.click("#undo")
    page.wait_for_function(f"document.getElementById('fit-id').textContent === '{base_id}'")
    settled(page)
    page.locator("input[name=channel][value='0']").check()
    posted, answered = [], []
    refit = lambda url: url.split("?")[0].endswith("/fits/from-curves")  # noqa: E731
    page.on("request", lambda r: posted.append(r) if refit(r.url) else None)
    page.on("response", lambda r: answered.append(r) if refit(r.url) else None)

    handle = page.locator("circle.handle.c0[data-angle='50']")
    # The page had scrolled by 306 px between the radio's check and the drag (scrollY 65 -> 371, seen
    # since the studio's panels joined the page; its cause not found yet): the handle is brought into view.
    handle.scroll_into_view_if_needed()
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    shown_during_drag = set()
    for step in range(1, 31):
        page.mouse.move(x, y + 3 * step)
        page.wait_for_timeout(40)
        shown_during_drag.add(page.evaluate("document.getElementById('preview').dataset.fit"))
    page.mouse.up()
    final_id = settled(page)

    # Several refits while the pointer moved, fewer than pointer moves.
    assert 3 <= len(posted) <= 31, len(posted)
    # The preview followed: it showed refits before the drag ended.
    assert len(shown_during_drag - {base_id}) >= 2
    assert final_id != base_id
    assert page.get_attribute("#preview", "data-fit") == final_id
    # The fit on screen is the fit of the curves on screen: the last request
    # carried the edited target as the page holds it.
    last = posted[-1].post_data_json
    assert answered[-1].json()["id"] == final_id
    # Live refits (warm-started from the fit on screen) while the pointer
    # moved, a full refit on release; each answer carried its curves.
    live = [r.post_data_json for r in posted[:-1]]
    assert sum(1 for b in live if b.get("live")) >= 2, live
    assert all(b["start_fit"] for b in live if b.get("live"))
    assert "live" not in last and last["draft"] is True
    assert answered[-1].json()["curves"]["fit_id"] == final_id
    target = page.evaluate("(() => { const d = document.querySelector('path.target.c0').getAttribute('d');"
                           " return d; })()")
    assert len(last["curves"]) == 1 and last["curves"][0]["eta_i"] == 1.5
    handle_value = float(handle.get_attribute("aria-valuenow"))
    theta = last["curves"][0]["angle_deg"]
    assert last["curves"][0]["rgb"][theta.index(50)][0] == pytest.approx(handle_value, abs=1e-3)  # aria-valuenow
    # has 3 decimals (static/plot.js): within 5e-4, so 1e-3 is two half-units
    assert target  # drawn
    # Undo is one step for the whole drag.
    page.click("#undo")
    page.wait_for_function(f"document.getElementById('fit-id').textContent === '{base_id}'")
    assert settled(page) == base_id


def test_503_is_retried_and_its_message_cleared(pages, editor_url):
    page = pages.new()
    pages.expected.append("503")
    open_editor(page, editor_url)
    base_id = settled(page)
    refused = []

    def busy_twice(route):
        if len(refused) < 2:
            refused.append(route.request)
            route.fulfill(status=503, content_type="application/json",
                          headers={"Retry-After": "1"},
                          body=json.dumps({"detail": "too many fits in flight (COATED_MAX_IN_FLIGHT)"}))
        else:
            route.continue_()

    page.route(FROM_CURVES, busy_twice)
    page.locator("input[name=channel][value='1']").check()
    point = page.locator("circle.handle.c1[data-angle='36']")
    point.focus()
    page.keyboard.press("Shift+ArrowUp")
    message = page.locator("#message")
    page.wait_for_function("document.getElementById('message').textContent.includes('busy')")
    assert "retrying" in message.inner_text()
    # Meanwhile the page says it is updating; the old fit is still the one shown, consistently.
    assert page.is_visible("#preview-state")
    assert page.inner_text("#fit-id") == base_id == page.get_attribute("#preview", "data-fit")
    new_id = page.wait_for_function(
        f"(() => {{ const id = document.getElementById('fit-id').textContent;"
        f" return id !== '{base_id}' && id; }})()").json_value()
    assert settled(page) == new_id
    assert len(refused) == 2
    assert message.inner_text() == ""
