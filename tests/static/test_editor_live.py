"""
Live editing in a real Chromium against a real server: a continuous drag
is refitted in the page while the pointer moves (no request; the first
move's curve is the server's live step's from the same start), the page
says so (for the exact-Fresnel kind too: its n, k the server's live step's),
and on release the server's full refit replaces it: the preview
shows the fit whose id is on screen, fitted to the curves on screen; a pointer at rest asks
for the full refit while it holds the point, and the release ends on that refit; a 503 is
retried with backoff, its message shown while it lasts and cleared by the next answer.
"""

from __future__ import annotations

import json
import re

import pytest
from playwright.sync_api import expect
from editor_pages import editor_url, open_editor, pages, chromium, live_server, settled  # noqa: F401 (fixtures: one server and one Chromium a module)

pytestmark = [pytest.mark.server, pytest.mark.browser]

FROM_CURVES = re.compile(r".*/api/v1/fits/from-curves(\?.*)?$")  # with or without its query


IN_PAGE = "cfTelemetry.shown.filter((s) => s.live === 'page')"


def refits(page):
    """The page's refit requests and their answers from now on (two lists that fill as they come)."""
    posted, answered = [], []
    page.on("request", lambda r: posted.append(r) if FROM_CURVES.match(r.url) else None)
    page.on("response", lambda r: answered.append(r) if FROM_CURVES.match(r.url) else None)
    return posted, answered


def watch_sends(page):
    """Log, in the page, each refit request's time, the time of the edit before it and whether it was a
    live step, and the time of the pointer's release (read by sends_while_held)."""
    page.evaluate(
        """() => { const send = window.fetch; window.cfSent = []; window.cfUp = Infinity;
             window.addEventListener('pointerup', () => { window.cfUp = performance.now(); }, true);
             window.fetch = (url, init) => { if (String(url).includes('/fits/from-curves'))
               window.cfSent.push({ at: performance.now(), editAt: cfTelemetry.lastEditAt,
                                    live: 'live' in JSON.parse(init.body) });
               return send(url, init); }; }"""
    )


def sends_while_held(page):
    """The refit requests since watch_sends, and those of them sent before the release, each checked to be
    the full refit of a pointer at rest: a moving pointer sends nothing (every refit is the page's own),
    but on a busy machine a gap between two moves can pass the rest (REST_MS, 500 ms, static/editor.js;
    a CI run saw one), and the page then rightly asks for the full refit of the point it holds."""
    sent, up = page.evaluate("[window.cfSent, window.cfUp]")
    during = [s for s in sent if s["at"] < up]
    for times in during:
        assert not times["live"] and times["at"] - times["editAt"] >= 499, (times, up)
    return sent, during


def handle_at(page, channel: int, angle: int):
    """The control point of ``channel`` at ``angle`` brought into view, and its centre (x, y)."""
    handle = page.locator(f"circle.handle.c{channel}[data-angle='{angle}']")
    handle.scroll_into_view_if_needed()
    box = handle.bounding_box()
    return handle, box["x"] + box["width"] / 2, box["y"] + box["height"] / 2


def test_continuous_drag_refits_in_the_page_and_ends_on_the_server_fit(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    base_id = settled(page)
    # A first edit warms the fitting worker (its base grid of the material).
    page.locator("input[name=channel][value='2']").check()
    page.locator("circle.handle.c2[data-angle='20']").focus()
    page.keyboard.press("ArrowUp")
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{base_id}'")
    page.click("#undo")
    page.wait_for_function(f"document.getElementById('fit-id').textContent === '{base_id}'")
    settled(page)
    expect(page.locator("#fit-source")).to_have_text("server fit")
    page.locator("input[name=channel][value='0']").check()
    posted, answered = refits(page)

    # The page had scrolled by 306 px between the radio's check and the drag (scrollY 65 -> 371, seen
    # since the studio's panels joined the page; its cause not found yet): the handle is brought into view.
    handle, x, y = handle_at(page, 0, 50)
    page.mouse.move(x, y)
    watch_sends(page)
    page.mouse.down()
    # The first move is solved in the page from the fit on screen (the base fit): the server's
    # live step from the same start on the same edit lands on the same curve (checked at the end).
    page.mouse.move(x, y + 6)
    page.wait_for_function(f"{IN_PAGE}.length >= 1")
    expect(page.locator("#fit-source")).to_have_text("live (in page)")
    first = page.evaluate(f"{IN_PAGE}[0]")
    shown_during_drag = set()
    for step in range(2, 31):
        page.mouse.move(x, y + 3 * step)
        page.wait_for_timeout(40)
        shown_during_drag.add(page.evaluate("document.getElementById('preview').dataset.fit"))
    assert len({f for f in shown_during_drag if f.startswith("in-page-")}) >= 2, shown_during_drag
    assert page.locator("#fit-id").text_content() == base_id  # ids, figures and downloads stay the server's
    page.mouse.up()
    final_id = settled(page)
    expect(page.locator("#fit-source")).to_have_text("server fit")

    # No request while the pointer moved: every refit was the page's own (or a rest's full refit).
    sent, during = sends_while_held(page)
    # The full refit on release replaces the page's: one request, not live, its answer on screen (or,
    # after a rest, the rest's request, when it was already asked for the edits released).
    assert len(sent) == len(during) + 1 or (during and len(sent) == len(during)), sent
    last = posted[-1].post_data_json
    assert "live" not in last and last["draft"] is True
    assert final_id != base_id
    assert answered[-1].json()["id"] == final_id
    assert page.get_attribute("#preview", "data-fit") == final_id
    assert answered[-1].json()["curves"]["fit_id"] == final_id
    assert len(last["curves"]) == 1 and last["curves"][0]["eta_i"] == 1.5
    handle_value = float(handle.get_attribute("aria-valuenow"))
    theta = last["curves"][0]["angle_deg"]
    assert last["curves"][0]["rgb"][theta.index(50)][0] == pytest.approx(handle_value, abs=1e-3)  # aria-valuenow
    # has 3 decimals (static/plot.js): within 5e-4, so 1e-3 is two half-units
    # Undo is one step for the whole drag.
    page.click("#undo")
    page.wait_for_function(f"document.getElementById('fit-id').textContent === '{base_id}'")
    assert settled(page) == base_id
    # The first move against the server's live step from the same start on the same edit (checked after the
    # drag: a pointer resting 500 ms on a point asks for the full refit, so the drag goes on at once).
    theta = page.evaluate("Array.from({length: 46}, (_, i) => 2 * i)")
    server = page.evaluate(
        """async ([base, theta, edits]) => {
             const body = { name: "live check", base: { fit: base }, draft: true, live: true, start_fit: base,
                            curves: Object.keys(edits).map((eta) => ({ eta_i: Number(eta), angle_deg: theta,
                                                                        rgb: edits[eta] })) };
             const r = await fetch(`/api/v1/fits/from-curves?curves_eta_i=1.5&curves_samples=46`,
                                   { method: "POST", headers: { "Content-Type": "application/json" },
                                     body: JSON.stringify(body) });
             return r.json(); }""",
        [base_id, theta, first["edits"]],
    )
    mine = page.evaluate(
        """([C, theta]) => theta.map((t) => { const mu = t === 90 ? 0 : Math.cos(t * Math.PI / 180);
             return [0, 1, 2].map((c) => { const P = ["F0", "a", "alpha"].map((p) =>
               C[p][c].reduce((s, v, j) => s + v * (1 / 3) ** j, 0));
               return P[0] + (1 - P[0]) * (1 - mu) ** 5 - P[1] * mu * (1 - mu) ** Math.max(P[2], 1e-3); }); })""",
        [first["coefficients"], theta],
    )
    # t = 1/3 at eta_i 1.5 over the default domain [1, 2.5] (the powers 1, t, t^2 above).
    assert server["eta_i_range"] == [1.0, 2.5]
    worst = max(abs(a - b) for row_a, row_b in zip(mine, server["curves"]["model"]) for a, b in zip(row_a, row_b))
    # The page's base rows are the 1 nm reference, the server's its 5 nm grid (1e-4 apart): the
    # curves within 1e-3 reflectance (seen: 1e-4).
    assert worst < 1e-3, worst


def test_503_is_retried_and_its_message_cleared(pages, editor_url):
    page = pages.new()
    pages.expected.append("503")
    open_editor(page, editor_url)
    base_id = settled(page)
    refused = []

    def busy_twice(route):
        if len(refused) < 2:
            refused.append(route.request)
            route.fulfill(
                status=503,
                content_type="application/json",
                headers={"Retry-After": "1"},
                body=json.dumps({"detail": "too many fits in flight (COATED_MAX_IN_FLIGHT)"}),
            )
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
        f"(() => {{ const id = document.getElementById('fit-id').textContent; return id !== '{base_id}' && id; }})()"
    ).json_value()
    assert settled(page) == new_id
    assert len(refused) == 2
    assert message.inner_text() == ""


def test_rgb_conductor_drag_is_solved_in_the_page_as_the_server_would(pages, live_server):
    """The exact-Fresnel kind's live step in the page: no request while the pointer moves, and
    the first move's n, k the server's live step's on the same edit."""
    import loopback
    import numpy as np

    from fitting import curve_base_from_nk, library_material

    angles = np.linspace(0.0, 90.0, 19)
    mu = np.where(angles == 90.0, 0.0, np.cos(np.radians(angles)))
    rgb = curve_base_from_nk(library_material("Cu")).rgb(mu, 1.5)
    rgb[:, 2] *= 1.1
    body = {
        "name": "live copper",
        "base": {"material": "Cu"},
        "model": "rgb-conductor",
        "curves": [{"eta_i": 1.5, "angle_deg": angles.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}],
    }
    response = loopback.post(f"{live_server}/api/v1/fits/from-curves", json=body, timeout=300)
    assert response.status_code == 201, response.text
    fit = response.json()
    page = pages.new()
    open_editor(page, live_server + "/")
    page.select_option("#material", f"saved:{fit['material_id']}")
    expect(page.locator("#fit-id")).to_have_text(fit["id"])
    settled(page)
    page.locator("input[name=channel][value='2']").check()
    handle, x, y = handle_at(page, 2, 50)
    page.mouse.move(x, y)
    watch_sends(page)
    page.mouse.down()
    page.mouse.move(x, y + 6)
    page.wait_for_function(f"{IN_PAGE}.length >= 1", timeout=20_000)
    expect(page.locator("#fit-source")).to_have_text("live (in page)")
    # The pointer may hold still past the rest while the worker makes its first solve (a cold start):
    # only that full refit is sent.
    for step in range(2, 12):
        page.mouse.move(x, y + 3 * step)
        page.wait_for_timeout(40)
    sends_while_held(page)
    first = page.evaluate(f"{IN_PAGE}[0]")
    theta = page.evaluate("Array.from({length: 46}, (_, i) => 2 * i)")
    server = page.evaluate(
        """async ([base, theta, edits]) => {
             const body = { name: "live check", base: { fit: base }, draft: true, live: true, start_fit: base,
                            model: "rgb-conductor",
                            curves: Object.keys(edits).map((eta) => ({ eta_i: Number(eta), angle_deg: theta,
                                                                        rgb: edits[eta] })) };
             const r = await fetch("/api/v1/fits/from-curves", { method: "POST",
               headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
             return r.json(); }""",
        [fit["id"], theta, first["edits"]],
    )
    assert server["model"] == "rgb-conductor", server
    page.mouse.up()
    settled(page)
    # The page's base rows (the opened fit's curves) and the server's agree to rounding: n, k within
    # two float16 steps (2^-9 relative; seen: the same float16 values).
    mine = np.array([first["coefficients"][p] for p in ("n", "k")])
    theirs = np.array([server["coefficients"][p] for p in ("n", "k")])
    np.testing.assert_allclose(mine, theirs, rtol=2.0**-9, atol=2.0**-14)


def test_a_pointer_at_rest_asks_for_the_full_refit_and_the_release_ends_on_it(pages, editor_url):
    """Held still for more than 0.5 s, the point's full refit is asked while the pointer holds it; the
    release where it rested ends on that refit's answer (never a refit of other edits)."""
    page = pages.new()
    open_editor(page, editor_url)
    base_id = settled(page)
    page.locator("input[name=channel][value='0']").check()
    posted, answered = refits(page)
    handle, x, y = handle_at(page, 0, 50)
    watch_sends(page)
    page.mouse.move(x, y)
    page.mouse.down()
    for step in range(1, 6):
        page.mouse.move(x, y + 3 * step)
        page.wait_for_timeout(40)
    page.wait_for_timeout(1500)  # at rest
    # Every request while held is a rest's full refit (on a busy machine a gap between two moves can
    # pass the rest too, sends_while_held); the last is that of the point where the pointer rests.
    _, during = sends_while_held(page)
    assert during, "the full refit is asked while the pointer rests on the point"
    assert during[-1]["editAt"] == page.evaluate("cfTelemetry.lastEditAt"), (during, "not the point at rest")
    assert len(posted) == len(during), (len(posted), during)
    rest = posted[-1]
    assert "live" not in rest.post_data_json and "start_fit" not in rest.post_data_json
    page.mouse.up()
    final_id = settled(page)
    assert final_id != base_id
    # Asked again at the release only when it had already answered (the store answers the same fit).
    since_rest = posted[len(during) - 1 :]
    assert {json.dumps(r.post_data_json["curves"]) for r in since_rest} == {json.dumps(rest.post_data_json["curves"])}
    assert {r.json()["id"] for r in answered if r.request.post_data == rest.post_data} == {final_id}
    assert page.get_attribute("#preview", "data-fit") == final_id
    page.click("#undo")
    assert settled(page) == base_id
