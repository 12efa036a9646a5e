"""
The preview says why eta_i matters with the clear coat off (item
7): the metal's n, k count relative to the medium it is in, so eta_i
changes its colour with no coat on top; with the coat on the line goes.
"""

from __future__ import annotations

import pytest
from editor_pages import editor_url, open_editor, pages, chromium, live_server  # noqa: F401 (fixtures: one server and one Chromium a module)
from playwright.sync_api import expect

pytestmark = [pytest.mark.server, pytest.mark.browser]


def test_coat_off_says_why_eta_i_matters(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    why = page.locator("#coat-why")
    expect(why).to_be_visible()
    expect(why).to_contain_text("relative to that medium")
    page.check("#coat")
    expect(why).to_be_hidden()
    page.uncheck("#coat")
    expect(why).to_be_visible()
