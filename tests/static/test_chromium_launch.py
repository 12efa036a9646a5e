"""
The browser tests' Chromium (tests/static/editor_pages.py's ``launch``):
it keeps every feature playwright disables for automation and also
disables :data:`editor_pages.UNUSED_FEATURES`, so that a new browser
context loads no omnibox popup (a WebUI page in a renderer process of its
own), which a plain launch does.
"""

from __future__ import annotations

import editor_pages
import pytest
from editor_pages import UNUSED_FEATURES, chromium, disabled_features, launch, live_server  # noqa: F401 (fixtures)

pytestmark = [pytest.mark.server, pytest.mark.browser]


def _browser_ui(browser) -> list[str]:
    """The URLs of the browser's own UI pages once a new context has opened a page."""
    context = browser.new_context()
    try:
        context.new_page().goto("about:blank")
        session = browser.new_browser_cdp_session()
        try:
            targets = session.send("Target.getTargets")["targetInfos"]
        finally:
            session.detach()
        return [target["url"] for target in targets if target["type"] == "browser_ui"]
    finally:
        context.close()


def test_playwrights_disabled_features_are_kept_and_no_context_loads_an_omnibox_popup(chromium):
    plain = launch(editor_pages._CHROMIUM.playwright, plain=True)
    try:
        (playwrights,) = [set(switch) for switch in disabled_features(plain)]
        popups = _browser_ui(plain)
    finally:
        plain.close()
    assert "PaintHolding" in playwrights  # one of playwright's (a check that the list was read)
    # What is disabled is there by default: the popup's WebUI, loaded with the context's window.
    assert any(url.startswith("chrome://omnibox-popup") for url in popups), popups

    switches = disabled_features(chromium)
    # Chromium keeps the last switch only: it must hold playwright's list and ours.
    assert set(switches[-1]) == playwrights | set(UNUSED_FEATURES)
    assert _browser_ui(chromium) == []


def test_the_page_cost_benchmark_reads_a_load_by_kind_of_process(chromium, browser_server):
    """benchmarks/browser_page_cost.py's load: an editor settled in a new context, its CPU time by kind."""
    from benchmarks.browser_page_cost import KINDS, load_once

    wall, spent = load_once(chromium, browser_server.url + "/", {browser_server.process.pid})
    assert wall > 0
    assert set(spent) <= set(KINDS)
    assert spent["chromium_renderer"] > 0 and spent["chromium_browser"] > 0
