"""
Screenshots of the editor's views for docs/editor.md
=====================================================

Debian's headless Chromium against a real server (a fresh data directory),
driven as an artist would: the library searched, a coat preset and a typed
point, two saved materials (one renamed, one in the bin, versions listed,
a link copied), and compare mode (a fit and its edit). Writes
``docs/images/editor_{library,entry,materials,compare}.png``, and the README's
``docs/images/editor.png``: the whole editor at 1920 x 1080 with an edit on screen.

Command: ``.venv/bin/python benchmarks/editor_views.py [--out docs/images]``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from conftest import server_process  # noqa: E402

from benchmarks.editor_speed import ARGS, READY  # noqa: E402
from playwright.sync_api import expect, sync_playwright  # noqa: E402

SETTLED = (
    "() => !document.body.hasAttribute('aria-busy') && document.getElementById('preview-state').hidden"
    " && document.getElementById('preview').dataset.fit === document.getElementById('fit-id').textContent"
)


def settle(page) -> str:
    page.wait_for_function(SETTLED, timeout=120_000)
    return page.inner_text("#fit-id")


def key_edit(page, channel: int, angle: int, key: str, presses: int = 1) -> None:
    before = page.inner_text("#fit-id")
    page.locator(f"input[name=channel][value='{channel}']").check()
    page.locator(f"circle.handle.c{channel}[data-angle='{angle}']").focus()
    for _ in range(presses):
        page.keyboard.press(key)
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{before}'", timeout=120_000)
    settle(page)


def save(page, name: str, said: str) -> None:
    page.fill("#name", name)
    page.click("#save")
    expect(page.locator("#message")).to_contain_text(said, timeout=120_000)
    settle(page)


def clip(page, *selectors: str, pad: int = 8) -> dict:
    """The page region around every element of `selectors` (their bounding boxes' union)."""
    boxes = [page.locator(selector).bounding_box() for selector in selectors]
    x0, y0 = min(b["x"] for b in boxes) - pad, min(b["y"] for b in boxes) - pad
    x1 = max(b["x"] + b["width"] for b in boxes) + pad
    y1 = max(b["y"] + b["height"] for b in boxes) + pad
    return {"x": x0, "y": y0, "width": x1 - x0, "height": y1 - y0}


def shoot(page, out: Path) -> None:
    page.goto(page.url)
    page.wait_for_function(READY, timeout=120_000)
    settle(page)
    # The library, searched.
    page.fill("#library-search", "gold")
    expect(page.locator("#library-state")).to_contain_text("match “gold”", timeout=120_000)
    page.locator("#library-list li[data-id='Au']").hover()
    page.locator("section[aria-labelledby=library-heading]").screenshot(path=out / "editor_library.png")
    page.fill("#library-search", "")

    # A coat preset and a typed point.
    page.click("#coat-presets button[data-id='water']")
    page.wait_for_function("document.getElementById('plot').dataset.eta === '1.33'")
    settle(page)
    page.locator("input[name=channel][value='1']").check()
    page.locator("circle.handle.c1[data-angle='36']").focus()
    page.fill("#point-value", "0.8")
    page.press("#point-value", "Enter")
    settle(page)
    page.fill("#eta-typed", "2.7")
    page.press("#eta-typed", "Enter")
    page.screenshot(path=out / "editor_entry.png", clip=clip(page, "label[for=eta]", "#entry-message"))

    # Materials: two saved (versions of one), one renamed, one in the bin, a link.
    save(page, "Green gold", "Saved “Green gold”")
    key_edit(page, channel=0, angle=60, key="ArrowDown", presses=4)
    save(page, "Green gold", "version 2")
    page.select_option("#material", "library:Cu")
    settle(page)
    key_edit(page, channel=2, angle=50, key="Shift+ArrowUp")
    save(page, "Pale copper", "Saved “Pale copper”")
    page.select_option("#material", "library:Ag")
    settle(page)
    key_edit(page, channel=0, angle=36, key="Shift+ArrowDown")
    save(page, "Warm silver", "Saved “Warm silver”")
    page.locator("#saved-list li", has_text="Warm silver").get_by_role(
        "button", name="Delete Warm silver (to the bin)"
    ).click()
    expect(page.locator("#bin-count")).to_have_text("1")
    item = page.locator("#saved-list li", has_text="Pale copper")
    item.get_by_role("button", name="Rename Pale copper").click()
    field = page.locator("#saved-list input[type=text]")
    field.fill("Rose copper")
    field.press("Enter")
    expect(page.locator("#manage-message")).to_contain_text("Renamed")
    gold = page.locator("#saved-list li", has_text="Green gold")
    gold.get_by_role("button", name="Versions of Green gold").click()
    expect(page.locator("#versions-list li")).to_have_count(2)
    gold.get_by_role("button", name="Copy the link to Green gold").click()
    expect(page.locator("#manage-message")).to_contain_text("Link")
    page.click("#bin summary")
    page.locator("section[aria-labelledby=manage-heading]").screenshot(path=out / "editor_materials.png")

    # Compare mode: the saved edit, reopened with its edit, against its base (the fit and its edit), at eta_i 1.5.
    gold.get_by_role("button", name="Open Green gold").click()
    settle(page)
    page.fill("#eta-typed", "1.5")
    page.press("#eta-typed", "Enter")
    settle(page)
    page.click("#coat-presets button[data-id='glass']")
    page.click("#compare-base")
    page.wait_for_function("document.getElementById('compare-de').dataset.fit")
    page.wait_for_function("document.getElementById('preview-compare').dataset.fit")
    page.wait_for_timeout(500)
    page.evaluate("window.scrollTo(0, 0)")
    page.screenshot(
        path=out / "editor_compare.png", clip=clip(page, "#plot-heading", "#compare-readout", "#compare-caption")
    )


def shoot_window(page, out: Path) -> None:
    """The README's picture: the editor as it opens, at 1920 x 1080, with one edit refitted."""
    page.wait_for_function(READY, timeout=120_000)
    settle(page)
    key_edit(page, channel=0, angle=60, key="Shift+ArrowDown", presses=2)
    page.evaluate("window.scrollTo(0, 0)")
    page.screenshot(path=out / "editor.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp, server_process(Path(tmp) / "data") as server:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            errors = []
            page.on("pageerror", lambda error: errors.append(str(error)))
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.goto(server.url + "/")
            shoot(page, args.out)
            window = browser.new_page(viewport={"width": 1920, "height": 1080})
            window.on("pageerror", lambda error: errors.append(str(error)))
            window.goto(server.url + "/?material=Cu")
            shoot_window(window, args.out)
            browser.close()
            if errors:
                raise SystemExit(f"the page logged errors: {errors}")
    print(
        "wrote",
        *(args.out / f"editor_{v}.png" for v in ("library", "entry", "materials", "compare")),
        args.out / "editor.png",
    )


if __name__ == "__main__":
    main()
