"""
Shared fixtures and helpers of the editor's browser tests (import them:
`from editor_pages import pages, open_editor`): Debian's Chromium through
the Python playwright package (never a downloaded browser; launched
without the address bar's popup, :data:`UNUSED_FEATURES`), a real server
process, and a check that the page logged no error (uncaught exceptions
and console errors). The server and Chromium (``live_server``, ``chromium``)
are one of each a test process: the server is tests/conftest.py's
session-scoped ``browser_server`` (``live_server`` here overrides its
function-scoped ``live_server``), so a test must assume nothing of the store
but what it made; Chromium is launched by the first test that asks for it
and closed after the last test of a run of such tests and of the other
tests marked ``browser`` (tests/conftest.py's ``pytest_runtest_teardown``
calls :func:`release_chromium`), so that no other test runs beside it:
while a browser is open, playwright's sync API holds an asyncio loop on the
thread, and ``asyncio.run`` in another test would refuse to start. Each test has fresh browser contexts (no cookies,
storage or cache from another test).
:func:`camera_rays` is numpy's twin of the preview's camera
(shader_ball.frag), for the WebGL parity tests.
"""

from __future__ import annotations

import base64

import numpy as np
import pytest
from playwright.sync_api import expect, sync_playwright

CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-quic",
]
TIMEOUT_MS = 120_000  # first fits start worker processes
# expect() waits as long as the page's own calls: its 5 s default is a
# guess at the machine's speed (a save behind a refit on a loaded 2-core
# machine takes longer), and waiting longer asserts the same thing.
expect.set_options(timeout=TIMEOUT_MS)


class SharedChromium:
    """Chromium through Python playwright, launched on first use, until :meth:`close`."""

    def __init__(self) -> None:
        self.playwright = self.browser = None

    def get(self):
        if self.browser is None:
            self.playwright = sync_playwright().start()
            self.browser = launch(self.playwright)
        return self.browser

    def close(self) -> None:
        if self.browser is not None:
            try:
                self.browser.close()
            finally:
                self.playwright.stop()
                self.playwright = self.browser = None


_CHROMIUM = SharedChromium()


def release_chromium(nextitem) -> None:
    """
    Close the shared Chromium unless ``nextitem`` (the next test, or None)
    uses it or is marked ``browser``: a browser module's tests that draw
    nothing (its REST, CLI and type checks) run between those that do, and a
    launch is seconds of CPU; none of them runs an asyncio loop of its own.
    """
    if nextitem is None or not (
        "chromium" in getattr(nextitem, "fixturenames", ()) or nextitem.get_closest_marker("browser")
    ):
        _CHROMIUM.close()


@pytest.fixture(scope="module")
def live_server(browser_server):
    """The browser modules' one server (a test that saves must not assume an empty list)."""
    return browser_server.url


@pytest.fixture(scope="module")
def chromium(live_server):
    """The test process's one Chromium (launched unless it is running; see :func:`release_chromium`)."""
    return _CHROMIUM.get()


@pytest.fixture
def editor_url(live_server):
    return live_server + "/"


UNUSED_FEATURES = ("WebUIOmniboxPopup", "WebUIOmniboxAimPopup", "WebUIOmniboxFullPopup", "PreloadTopChromeWebUI")
"""
Chromium features that cost the tests CPU and do nothing for a page:
headless Chromium gives every window (one a browser context) an address
bar whose popup is a WebUI page, loaded at once in a renderer process of
its own (chrome://omnibox-popup.top-chrome). Disabled, a fresh context's
editor load takes less than half the renderer CPU time it took
(``benchmarks/browser_page_cost.py``).
"""

_disable_features: str | None = None  # the launch switch, once read (see disable_features)


def disabled_features(browser) -> list[list[str]]:
    """Each ``--disable-features=`` switch of ``browser``'s command line (chrome://version): its features, in order."""
    page = browser.new_page()
    try:
        page.goto("chrome://version")
        switches = page.inner_text("#command_line").split()
    finally:
        page.close()
    return [s.split("=", 1)[1].split(",") for s in switches if s.startswith("--disable-features=")]


def disable_features(p) -> str:
    """
    ``--disable-features=`` with playwright's own list and
    :data:`UNUSED_FEATURES`. Chromium keeps only the last of several such
    switches, and playwright passes its list (features that break
    automation) before the caller's arguments, so a switch of ours alone
    would enable those again. Its list is read from a plain launch's
    command line (:func:`disabled_features`), once a process.
    """
    global _disable_features
    if _disable_features is None:
        browser = launch(p, plain=True)
        try:
            playwrights = [feature for switch in disabled_features(browser) for feature in switch if feature]
        finally:
            browser.close()
        _disable_features = "--disable-features=" + ",".join(dict.fromkeys([*playwrights, *UNUSED_FEATURES]))
    return _disable_features


def launch(p, plain: bool = False):
    """Chromium with :data:`CHROMIUM_ARGS` and, unless ``plain``, :data:`UNUSED_FEATURES` disabled."""
    return p.chromium.launch(
        executable_path="/usr/bin/chromium", args=CHROMIUM_ARGS if plain else [*CHROMIUM_ARGS, disable_features(p)]
    )


class Pages:
    """Pages of one Chromium; each checked for logged errors at the end."""

    def __init__(self, browser) -> None:
        self.browser = browser
        self.errors: list[str] = []
        self.expected: list[str] = []  # substrings of console errors a test provokes on purpose
        self.contexts: list = []

    def new(self, width: int = 1400, height: int = 900):
        context = self.browser.new_context(viewport={"width": width, "height": height}, accept_downloads=True)
        self.contexts.append(context)
        page = context.new_page()
        page.set_default_timeout(TIMEOUT_MS)
        page.on("pageerror", lambda error: self.errors.append(f"uncaught: {error}"))
        page.on("console", lambda m: self.errors.append(f"console: {m.text}") if m.type == "error" else None)
        return page


@pytest.fixture
def pages(chromium):
    """
    ``pages.new(width, height)``: a fresh page in a fresh context; no page
    may log an error. Its contexts close at the end of the test (before the
    server stops: a page still fetching then would log a refused connection).
    """
    made = Pages(chromium)
    yield made
    for context in made.contexts:
        context.close()
    unexpected = [e for e in made.errors if not any(s in e for s in made.expected)]
    assert not unexpected, unexpected


def settled(page):
    """Wait until nothing is in flight and the preview draws the fit on screen; that fit's id."""
    page.wait_for_function(
        "() => { const id = document.getElementById('fit-id').textContent;"
        " return !document.body.hasAttribute('aria-busy')"
        " && document.getElementById('preview-state').hidden"
        " && document.getElementById('preview').dataset.fit === id; }"
    )
    return page.inner_text("#fit-id")


def key_edit(page, channel=1, angle=36, key="Shift+ArrowUp"):
    """Move a control point by one key press; wait for its refit on screen. The refit's id."""
    before = page.inner_text("#fit-id")
    page.locator(f"input[name=channel][value='{channel}']").check()
    page.locator(f"circle.handle.c{channel}[data-angle='{angle}']").focus()
    page.keyboard.press(key)
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{before}'")
    return settled(page)


def open_editor(page, url):
    page.goto(url)
    page.wait_for_selector("body[data-ready=true]")
    page.wait_for_function("!document.body.hasAttribute('aria-busy')")


F32_BASE64 = """const f32 = (floats) => {
    const bytes = new Uint8Array(Float32Array.from(floats).buffer);
    let text = '';
    for (let i = 0; i < bytes.length; i += 32768) text += String.fromCharCode.apply(null, bytes.subarray(i, i + 32768));
    return btoa(text);
};"""
"""
JavaScript: ``f32(floats)``, float32 values (a Float32Array, or numbers
that are float32 values) as base64 of their little-endian bytes; read with
:func:`from_f32`. The same values as ``Array.from``, exactly, but one
string: playwright checks a returned array number by number (10 s of a
three.js parity test went to checking 65,536 numbers a read).
"""


def from_f32(text: str) -> np.ndarray:
    """The float32 values of ``f32(...)`` (:data:`F32_BASE64`) as float64."""
    return np.frombuffer(base64.b64decode(text), dtype="<f4").astype(np.float64)


def read_float(page, output: str, width: int, height: int) -> np.ndarray:
    """(height, width, 4) floats of the preview's OUTPUT.<output> (a float target), top row first."""
    flat = page.evaluate(
        f"""async () => {{
            {F32_BASE64}
            const {{ OUTPUT }} = await import('/preview.js');
            return f32(window.cfPreview.readFloat(OUTPUT.{output}, {width}, {height}));
        }}"""
    )
    return from_f32(flat).reshape(height, width, 4)[::-1]


def camera_rays(yaw, pitch, distance, fov, width, height, bands=3):
    """
    numpy of shader_ball.frag's camera at width x height pixels (top row
    first): NdotV, the hit mask, the band index of each pixel and the
    mirror direction R (world, unit) on the unit sphere.
    """
    y, x = np.mgrid[0:height, 0:width]
    frag = np.stack([x + 0.5, (height - 1 - y) + 0.5], axis=-1)
    eye = distance * np.array([np.cos(pitch) * np.sin(yaw), np.sin(pitch), np.cos(pitch) * np.cos(yaw)])
    forward = -eye / np.linalg.norm(eye)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    ndc = (2.0 * frag - np.array([width, height])) / height
    focal = np.tan(0.5 * fov)
    d = forward + focal * (ndc[..., :1] * right + ndc[..., 1:] * up)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = d @ eye
    disc = b * b - (eye @ eye - 1.0)
    hit = disc > 0
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    N = eye + t[..., None] * d
    N /= np.linalg.norm(N, axis=-1, keepdims=True)
    cos = np.sum(N * -d, axis=-1)
    R = d + 2.0 * cos[..., None] * N
    band = np.clip(np.floor(frag[..., 0] * bands / width), 0, bands - 1).astype(int)
    return np.clip(cos, 0.0, 1.0), hit, band, R
