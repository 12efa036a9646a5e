"""
Shared fixtures of the editor's browser tests (import them: `from editor_pages import pages, open_editor`): Debian's Chromium through the
Python playwright package (never a downloaded browser), a real server
process (tests/conftest.py's live_server), and a check that the page logged
no error (uncaught exceptions and console errors).
"""

from __future__ import annotations

import pytest
from playwright.sync_api import sync_playwright

CHROMIUM_ARGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic",
]
TIMEOUT_MS = 120_000  # first fits start worker processes


@pytest.fixture
def editor_url(live_server):
    return live_server + "/"


def launch(p):
    return p.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS)


class Pages:
    """Pages of one Chromium; each checked for logged errors at the end."""

    def __init__(self, browser) -> None:
        self.browser = browser
        self.errors: list[str] = []
        self.expected: list[str] = []  # substrings of console errors a test provokes on purpose

    def new(self, width: int = 1400, height: int = 900):
        context = self.browser.new_context(viewport={"width": width, "height": height}, accept_downloads=True)
        page = context.new_page()
        page.set_default_timeout(TIMEOUT_MS)
        page.on("pageerror", lambda error: self.errors.append(f"uncaught: {error}"))
        page.on("console", lambda m: self.errors.append(f"console: {m.text}") if m.type == "error" else None)
        return page


@pytest.fixture
def pages(live_server):
    """
    ``pages.new(width, height)``: a fresh page; no page may log an error.
    It depends on the server so that the browser closes before the server
    stops (a page still fetching then would log a refused connection).
    """
    with sync_playwright() as p:
        browser = launch(p)
        made = Pages(browser)
        yield made
        browser.close()
        unexpected = [e for e in made.errors if not any(s in e for s in made.expected)]
        assert not unexpected, unexpected


def open_editor(page, url):
    page.goto(url)
    page.wait_for_selector("body[data-ready=true]")
    page.wait_for_function("!document.body.hasAttribute('aria-busy')")
