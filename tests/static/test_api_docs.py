"""
The API docs at ``/docs`` render in a real Chromium, offline.

Swagger UI (npm ``swagger-ui-dist``, scripts/swagger-ui/package-lock.json)
is served by the service at ``/vendor/swagger-ui/``; every request that
would leave loopback is blocked and recorded (a CDN script, a font, the
validator badge), and the page must show every operation of
``/openapi.json`` (an OpenAPI 3.1 document, which the Swagger UI 4 bundled
before could not read) and its schemas, with no console error.
"""

from __future__ import annotations

from urllib.parse import urlsplit

import pytest
import requests
from editor_pages import chromium, live_server, pages  # noqa: F401  (shared fixtures)
from playwright.sync_api import expect

pytestmark = [pytest.mark.server, pytest.mark.browser, pytest.mark.slow]

LOOPBACK = {"127.0.0.1"}


def _offline(page) -> list[str]:
    """Abort every request to a host other than loopback; return the list of those blocked."""
    blocked: list[str] = []

    def handle(route):
        if urlsplit(route.request.url).hostname in LOOPBACK:
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    page.context.route("**/*", handle)
    return blocked


def test_docs_render_every_operation_and_the_schemas(pages, live_server):
    spec = requests.get(live_server + "/openapi.json", timeout=30).json()
    assert spec["openapi"].startswith("3.1")
    # Swagger UI draws an operation once under each of its tags (GET /fits/{id}/edit is under two).
    operations = sum(
        len(op.get("tags") or ["default"])
        for item in spec["paths"].values()
        for method, op in item.items()
        if method in ("get", "post", "put", "patch", "delete")
    )
    schemas = spec["components"]["schemas"]
    page = pages.new(1280, 900)
    blocked = _offline(page)
    page.goto(live_server + "/docs")
    expect(page.locator(".swagger-ui .info .title")).to_contain_text(spec["info"]["title"])
    expect(page.locator(".opblock")).to_have_count(operations)
    assert page.locator("text=Unable to render this definition").count() == 0
    # One operation by its path, as a reader finds it.
    expect(page.locator(".opblock-summary-path", has_text="/api/v1/materials").first).to_be_visible()
    # The schemas section lists the document's components, each by its title.
    titles = page.locator(
        "section.models article[data-json-schema-level='0'] > .json-schema-2020-12-head .json-schema-2020-12__title"
    )
    expect(titles).to_have_count(len(schemas))
    assert set(titles.all_text_contents()) == {s.get("title", name) for name, s in schemas.items()}
    # An operation opens, with its parameters and answers.
    page.locator(".opblock-summary-path", has_text="/api/v1/fits/{fit_id}/pack").first.click()
    expect(page.locator(".opblock.is-open .parameters-container")).to_contain_text("format")
    assert blocked == [], blocked


def test_swagger_ui_is_the_pinned_version():
    """The served assets are those of the lock file (scripts/bootstrap installs them)."""
    import json

    from service.main import SWAGGER_UI_DIR

    lock = json.loads((SWAGGER_UI_DIR.parents[1] / "package-lock.json").read_text())
    installed = json.loads((SWAGGER_UI_DIR / "package.json").read_text())
    assert installed["version"] == lock["packages"]["node_modules/swagger-ui-dist"]["version"]
    assert int(installed["version"].split(".")[0]) >= 5  # OpenAPI 3.1 needs Swagger UI 5
