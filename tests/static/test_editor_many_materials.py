"""
Every saved material, however many: with 2,000 saved materials in the
store (four pages of the service's 500), the one saved first and the one
saved last are both in the picker and in "My materials", both are found by
the search (asked of the service), and the name-clash question of a save
asks the service, so a name far past the first page is still asked about.
A real server over a real SQLite store, driven in a real Chromium.
"""

from __future__ import annotations

import hashlib

import pytest
from conftest import server_process
from editor_pages import chromium, key_edit, open_editor, pages, settled  # noqa: F401 (fixtures)
from playwright.sync_api import expect

from service.store import FitRecord, SQLiteStore

pytestmark = [pytest.mark.server, pytest.mark.browser, pytest.mark.slow]

COUNT = 2000


def _id(i: int) -> str:
    return hashlib.sha256(f"bulk {i}".encode()).hexdigest()[:32]


def _name(i: int) -> str:
    return f"bulk material {i:04d}"


@pytest.fixture(scope="module")
def live_server(tmp_path_factory):
    """A server whose store already holds :data:`COUNT` saved edited materials, oldest first."""
    data = tmp_path_factory.mktemp("many") / "data"
    data.mkdir(parents=True)
    store = SQLiteStore(data / "store.sqlite3")
    try:
        for i in range(COUNT):
            store.put_fit(
                FitRecord(
                    id=_id(i),
                    kind="curves",
                    material_id=_id(i),
                    name=_name(i),
                    source="edit",
                    material={"name": _name(i), "coefficients": {"F0": [[0.5]] * 3}},
                    metrics={"x": 1.0},
                )
            )
    finally:
        store.close()
    with server_process(data) as server:
        yield server.url


def test_the_first_and_the_last_of_2000_are_listed_and_found(pages, live_server):
    page = pages.new()
    open_editor(page, live_server + "/")
    settled(page)
    first, last = f"saved:{_id(0)}", f"saved:{_id(COUNT - 1)}"
    for value in (first, last):
        expect(page.locator(f"#material option[value='{value}']")).to_have_count(1)
    assert page.locator("#material optgroup[label='Saved'] option").count() == COUNT
    expect(page.locator("#saved-state")).to_have_text(f"{COUNT} saved materials.")
    for i in (0, COUNT - 1):
        page.fill("#saved-search", _name(i))
        expect(page.locator("#saved-state")).to_have_text(f"1 of {COUNT} match “{_name(i)}”.")
        expect(page.locator("#saved-list li")).to_have_count(1)
        expect(page.locator(f"#saved-list li[data-id='{_id(i)}'] .title")).to_have_text(_name(i))
    page.fill("#saved-search", "bulk material 19")
    expect(page.locator("#saved-state")).to_have_text(f"100 of {COUNT} match “bulk material 19”.")
    # Saving an edit under the last one's name asks first: the service knows the name.
    key_edit(page)
    page.fill("#name", _name(COUNT - 1))
    asked = []
    page.once("dialog", lambda dialog: (asked.append(dialog.message), dialog.dismiss()))
    page.click("#save")
    expect(page.locator("#message")).to_contain_text("Not saved: choose another name")
    assert asked and _name(COUNT - 1) in asked[0]
