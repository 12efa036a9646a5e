"""
Materials an artist manages, against a real server that requires its write
token (``COATED_API_TOKEN``): every save is a version (listed, each opened
and downloaded by id), a rename keeps the history and the next save, a
delete is a bin (only with the token; nothing is lost; restore), uploads
are kept apart from saved edits, and a fit reopens with its edit
(``GET /fits/{id}/edit``); a stale save (``expected_version`` read before a
rename or a delete) is 409 naming what changed, a save that restores from
the bin says so, identical saves are one version, and ``POST /packs``
needs the token. Then the library to browse and the coat presets, and the
upload form's ``min_coverage``. One server for the module.
"""

from __future__ import annotations

import re

import httpx
import loopback
import numpy as np
import pytest
from conftest import server_process

from fitting.domain import COAT_PRESETS
from fitting.fits.curves_base import curve_base_from_nk
from fitting.optics.catalogue import catalogue, search_catalogue
from fitting.optics.library import LIBRARY_NAMES, library_material
from service.schemas import MATERIAL_ID_PATTERN

pytestmark = [pytest.mark.server, pytest.mark.slow]

API = "/api/v1"
TOKEN = "studio-test-token"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
ANGLE = np.linspace(0.0, 90.0, 19)
SAVES_PER_MINUTE = 120
"""The module server's COATED_SAVES_PER_CLIENT_PER_MINUTE: over twice the saves its other tests make
(about 50), under the repeats test_identical_saves_are_one_version sends (the service default is 600)."""


def gold_curve(red_scale: float, eta_i: float = 1.5) -> dict:
    mu = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))
    rgb = curve_base_from_nk(library_material("Au")).rgb(mu, eta_i)
    rgb[:, 0] *= 1.0 - (1.0 - red_scale) * (1.0 - (ANGLE / 90.0) ** 4)
    return {"eta_i": eta_i, "angle_deg": ANGLE.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}


def nk_csv(shift: float = 0.0, lo: float = 350.0, hi: float = 850.0) -> str:
    wavelength = np.linspace(lo, hi, 26)
    n = 0.2 + 1.3 * np.exp(-(((wavelength - 350.0) / 150.0) ** 2)) + shift
    k = 1.8 + 4.0 * (wavelength - 350.0) / 500.0
    return "wavelength_nm,n,k\n" + "".join(f"{w},{a},{b}\n" for w, a, b in zip(wavelength, n, k))


@pytest.fixture(scope="module")
def http(tmp_path_factory):
    data = tmp_path_factory.mktemp("materials") / "data"
    with server_process(
        data,
        COATED_API_TOKEN=TOKEN,
        COATED_REQUIRE_TOKEN="true",
        COATED_SAVES_PER_CLIENT_PER_MINUTE=str(SAVES_PER_MINUTE),
    ) as server:
        with loopback.Client(base_url=server.url, timeout=300) as client:
            yield client


def save(http, name: str, red_scale: float, **extra) -> httpx.Response:
    body = {"name": name, "base": {"material": "Au"}, "curves": [gold_curve(red_scale)], **extra}
    return http.post(f"{API}/fits/from-curves", json=body, headers=AUTH)


def listed(http, **params) -> list[dict]:
    response = http.get(f"{API}/materials", params=params)
    assert response.status_code == 200, response.text
    return [m for m in response.json()["materials"] if m["kind"] != "library"]


@pytest.fixture(scope="module")
def brass(http):
    """A material saved twice: two versions."""
    first = save(http, "studio brass", 0.9)
    assert first.status_code == 201, first.text
    second = save(http, "studio brass", 0.8, expected_version=1)
    assert second.status_code == 201, second.text
    assert first.json()["material_id"] == second.json()["material_id"]
    return first.json(), second.json()


def test_each_save_is_a_version_opened_and_downloaded_by_id(http, brass):
    first, second = brass
    material_id = first["material_id"]
    answer = http.get(f"{API}/materials/{material_id}/versions").json()
    assert answer["version"] == 2 and answer["next_before"] is None
    assert [(v["version"], v["fit_id"]) for v in answer["versions"]] == [(2, second["id"]), (1, first["id"])]
    one = answer["versions"][1]
    assert one["name"] == "studio brass" and one["kind"] == "curves"
    assert one["delta_E_mean"] == first["metrics"]["model"]["delta_E_mean"]
    assert one["share_url"] == f"/?material={material_id}&version=1"
    opened = http.get(f"{API}/materials/{material_id}/versions/1")
    assert opened.status_code == 200 and opened.json()["id"] == first["id"]
    download = http.get(one["pack_url"], params={"format": "json"})
    assert download.status_code == 200 and download.json()["materials"][0]["name"] == "studio brass"
    # Paged: one at a time, newest first.
    page = http.get(f"{API}/materials/{material_id}/versions", params={"limit": 1}).json()
    assert [v["version"] for v in page["versions"]] == [2] and page["next_before"] == 2
    older = http.get(
        f"{API}/materials/{material_id}/versions", params={"limit": 1, "before": page["next_before"]}
    ).json()
    assert [v["version"] for v in older["versions"]] == [1] and older["next_before"] is None
    assert http.get(f"{API}/materials/{material_id}/versions/3").status_code == 404
    assert http.get(f"{API}/materials/{'0' * 32}/versions").status_code == 404
    assert http.get(f"{API}/materials/{material_id}/versions/0").status_code == 422


def test_a_fit_reopens_with_its_edit(http, brass):
    _, second = brass
    edit = http.get(f"{API}/fits/{second['id']}/edit").json()
    assert edit["kind"] == "curves" and edit["material_id"] == second["material_id"]
    assert edit["base"] == {"material": "Au"} and edit["version"] == 2
    request = edit["request"]
    assert request["base"] == {"material": "Au"} and request["name"] == "studio brass"
    assert len(request["curves"]) == 1 and request["curves"][0]["eta_i"] == 1.5
    # The edit posted again is the same fit (served from the store), and nothing changed: no new version.
    again = http.post(f"{API}/fits/from-curves", json={**request, "expected_version": 2}, headers=AUTH)
    assert again.status_code == 200 and again.json()["id"] == second["id"]
    assert http.get(f"{API}/materials/{second['material_id']}").json()["version"] == 2
    # A library fit has no edit: it opens as its base.
    gold = http.post(f"{API}/fits", json={"material": "Au"}, headers=AUTH).json()
    library_edit = http.get(f"{API}/fits/{gold['id']}/edit").json()
    assert library_edit["base"] == {"material": "Au"} and library_edit["request"] is None
    assert http.get(f"{API}/fits/{'0' * 32}/edit").status_code == 404
    detail = http.get(f"{API}/materials/{second['material_id']}").json()
    assert detail["share_url"] == f"/?material={second['material_id']}"


def test_a_fit_by_name_or_symbol_any_case(http):
    gold = http.post(f"{API}/fits", json={"material": "Au"}, headers=AUTH).json()
    for named in ("gold", "GOLD", "au", " Gold "):
        fit = http.post(f"{API}/fits", json={"material": named}, headers=AUTH)
        assert fit.status_code in (200, 201) and fit.json()["id"] == gold["id"], named
    refused = http.post(f"{API}/fits", json={"material": "unobtainium"}, headers=AUTH)
    assert refused.status_code == 422 and "`material`" in refused.json()["detail"]
    near = http.post(f"{API}/fits", json={"material": "stainless steel 316"}, headers=AUTH)
    assert near.status_code == 422 and "did you mean stainless-steel.Karlsson-austenitic" in near.json()["detail"]
    assert http.get(f"{API}/materials/Ti.Johnson").json()["name"] == "titanium (Ti)"


def test_rename_keeps_the_history_and_the_next_save(http):
    a = save(http, "to rename", 0.85).json()
    material_id = a["material_id"]
    renamed = http.patch(f"{API}/materials/{material_id}", json={"name": "  renamed gold "}, headers=AUTH)
    assert renamed.status_code == 200, renamed.text
    assert (renamed.json()["name"], renamed.json()["version"]) == ("renamed gold", 1)
    assert [m["name"] for m in listed(http) if m["id"] == material_id] == ["renamed gold"]
    # The edit carries the new name; saved with its material_id it is the next version.
    request = http.get(f"{API}/fits/{a['id']}/edit").json()["request"]
    assert (request["name"], request["material_id"]) == ("renamed gold", material_id)
    request["curves"] = [gold_curve(0.75)]
    b = http.post(f"{API}/fits/from-curves", json={**request, "expected_version": 1}, headers=AUTH)
    assert b.status_code == 201, b.text
    assert b.json()["material_id"] == material_id and b.json()["name"] == "renamed gold"
    versions = http.get(f"{API}/materials/{material_id}/versions").json()
    assert [v["name"] for v in versions["versions"]] == ["renamed gold", "to rename"]
    # A save under the new name alone finds the material too.
    c = save(http, "renamed gold", 0.7)
    assert c.json()["material_id"] == material_id
    # The old name is free: a new material, which never mixes with the renamed one.
    fresh = save(http, "to rename", 0.85)
    assert fresh.status_code == 201 and fresh.json()["material_id"] != material_id
    assert fresh.json()["id"] != a["id"]
    assert http.get(f"{API}/materials/{material_id}").json()["version"] == 3
    # Names of edited materials are unique: a rename or a save onto another's name is 409.
    taken = http.patch(f"{API}/materials/{material_id}", json={"name": "to rename"}, headers=AUTH)
    assert taken.status_code == 409 and taken.json()["errors"][0]["loc"] == ["body", "name"]
    clash = save(http, "to rename", 0.6, material_id=material_id)
    assert clash.status_code == 409 and "another saved material" in clash.json()["detail"]
    # Refusals name the rule.
    assert http.patch(f"{API}/materials/Au", json={"name": "x"}, headers=AUTH).status_code == 422
    assert http.patch(f"{API}/materials/{'0' * 32}", json={"name": "x"}, headers=AUTH).status_code == 404
    assert http.patch(f"{API}/materials/{material_id}", json={"name": " "}, headers=AUTH).status_code == 422
    assert http.patch(f"{API}/materials/{material_id}", json={"name": "x"}).status_code == 401
    unknown = save(http, "ghost", 0.9, material_id="f" * 32)
    assert unknown.status_code == 404 and "material_id" in unknown.json()["detail"]


def test_delete_needs_the_token_and_loses_nothing(http):
    fit = save(http, "to delete", 0.95).json()
    material_id = fit["material_id"]
    refused = http.delete(f"{API}/materials/{material_id}")
    assert refused.status_code == 401 and "Bearer" in refused.json()["detail"]
    wrong = http.delete(f"{API}/materials/{material_id}", headers={"Authorization": "Bearer nope"})
    assert wrong.status_code == 401
    cross_site = http.delete(f"{API}/materials/{material_id}", headers={**AUTH, "Origin": "http://evil.example"})
    assert cross_site.status_code == 403
    assert material_id in [m["id"] for m in listed(http)]
    deleted = http.delete(f"{API}/materials/{material_id}", headers=AUTH)
    assert deleted.status_code == 200 and deleted.json()["deleted_at"] is not None
    assert material_id not in [m["id"] for m in listed(http)]
    assert [m["id"] for m in listed(http, deleted="true")] == [material_id]
    # Nothing is erased: the material, its fit, download and versions answer.
    assert http.get(f"{API}/materials/{material_id}").json()["deleted_at"] is not None
    assert http.get(f"{API}/fits/{fit['id']}").status_code == 200
    assert http.get(f"{API}/fits/{fit['id']}/pack").status_code == 200
    assert http.get(f"{API}/materials/{material_id}/versions").json()["version"] == 1
    again = http.delete(f"{API}/materials/{material_id}", headers=AUTH)
    assert again.status_code == 200 and again.json()["deleted_at"] == deleted.json()["deleted_at"]
    restored = http.post(f"{API}/materials/{material_id}/restore", headers=AUTH)
    assert restored.status_code == 200 and restored.json()["deleted_at"] is None
    assert material_id in [m["id"] for m in listed(http)]
    assert http.post(f"{API}/materials/{material_id}/restore").status_code == 401
    assert http.delete(f"{API}/materials/Au", headers=AUTH).status_code == 422
    assert http.delete(f"{API}/materials/{'0' * 32}", headers=AUTH).status_code == 404


def test_a_stale_save_does_not_undo_a_rename_or_a_delete(http):
    first = save(http, "stale gold", 0.9).json()
    material_id = first["material_id"]
    opened = http.get(f"{API}/fits/{first['id']}/edit").json()["request"]  # an editor, at version 1
    assert http.patch(f"{API}/materials/{material_id}", json={"name": "fresh gold"}, headers=AUTH).status_code == 200
    stale = http.post(
        f"{API}/fits/from-curves", headers=AUTH, json={**opened, "curves": [gold_curve(0.8)], "expected_version": 1}
    )
    assert stale.status_code == 409 and "renamed 'fresh gold'" in stale.json()["detail"], stale.text
    assert http.get(f"{API}/materials/{material_id}").json()["name"] == "fresh gold"
    assert http.delete(f"{API}/materials/{material_id}", headers=AUTH).status_code == 200
    again = http.post(
        f"{API}/fits/from-curves",
        headers=AUTH,
        json={**opened, "name": "fresh gold", "curves": [gold_curve(0.8)], "expected_version": 1},
    )
    assert again.status_code == 409 and "moved to the bin" in again.json()["detail"], again.text
    # Without `expected_version` the save takes it out of the bin, and says so.
    restoring = save(http, "fresh gold", 0.8, material_id=material_id)
    assert restoring.status_code == 201 and restoring.json()["restored_from_bin"] is True
    assert http.get(f"{API}/materials/{material_id}").json()["deleted_at"] is None
    assert save(http, "fresh gold", 0.75).json()["restored_from_bin"] is False


def test_identical_saves_are_one_version(http):
    # Repeats alone past the server's COATED_SAVES_PER_CLIENT_PER_MINUTE, over one kept-alive connection:
    # a repeat adds no version, so it is neither counted against the rate nor refused.
    repeats = SAVES_PER_MINUTE + 80
    answers = [http.post(f"{API}/fits", json={"material": "Ag"}, headers=AUTH) for _ in range(1 + repeats)]
    assert answers[0].status_code == 201 and {r.status_code for r in answers[1:]} == {200}
    assert len({r.json()["id"] for r in answers}) == 1
    assert http.get(f"{API}/materials/Ag").json()["version"] == 1
    assert len(http.get(f"{API}/materials/Ag/versions").json()["versions"]) == 1


def test_names_are_one_spelling_visible_and_not_a_built_in_material_s(http):
    nfd = save(http, "Cafe\u0301 brass", 0.9)
    nfc = save(http, "Caf\u00e9 brass", 0.85)
    assert nfd.status_code == 201 and nfc.json()["material_id"] == nfd.json()["material_id"]
    assert nfc.json()["name"] == "Caf\u00e9 brass"
    material_id = nfd.json()["material_id"]
    for name, rule in (
        ("Au", "reserved"),
        ("gold", "reserved"),
        ("\u200b\u200b", "visible character"),
        ("brass\u202eevil", "bidirectional control"),
    ):
        renamed = http.patch(f"{API}/materials/{material_id}", json={"name": name}, headers=AUTH)
        assert renamed.status_code == 422 and rule in renamed.json()["detail"], renamed.text
        assert save(http, name, 0.8).status_code == 422


def test_look_alike_names_are_one_name_and_every_catalogue_name_is_reserved(http):
    first = save(http, "Rose brass", 0.88)
    assert first.status_code == 201, first.text
    material_id = first.json()["material_id"]
    # A Cyrillic letter, another case, full width, a zero-width space, "rn" for "m": 409 naming the material.
    for name in ("R\u043ese brass", "rose brass", "\uff32ose brass", "Rose\u200b brass", "Rose brass rn"):
        if name.endswith("rn"):
            assert save(http, "Rose brass m", 0.87).status_code == 201
        answer = save(http, name, 0.86)
        assert answer.status_code == 409, answer.text
        detail = answer.json()["detail"]
        assert "looks the same as" in detail and "the name of saved material" in detail, detail
    # Every catalogue entry's names, symbol and id are reserved (not only the library's), through look-alikes.
    entry = next(e for e in catalogue().values() if not e["library"] and e["aliases"])
    for name in (entry["name"], entry["aliases"][0].upper(), entry["symbol"], entry["id"], "G\u043eld", "\uff21\uff55"):
        answer = save(http, name, 0.85)
        assert answer.status_code == 422 and "reserved" in answer.json()["detail"], answer.text
        renamed = http.patch(f"{API}/materials/{material_id}", json={"name": name}, headers=AUTH)
        assert renamed.status_code == 422 and "which names a material of the catalogue" in renamed.json()["detail"]
    assert http.get(f"{API}/materials/{material_id}").json()["name"] == "Rose brass"


def test_packs_need_the_token(http, brass):
    body = {"fit_ids": [brass[0]["id"]], "format": "json"}
    refused = http.post(f"{API}/packs", json=body)
    assert refused.status_code == 401 and "Bearer" in refused.json()["detail"]
    assert http.post(f"{API}/packs", json=body, headers={**AUTH, "Origin": "http://evil.example"}).status_code == 403
    assert http.post(f"{API}/packs", json=body, headers=AUTH).status_code == 200


def test_a_link_needs_the_token_and_a_saved_fit_s_never_expires(http, brass):
    fit_id = brass[0]["id"]
    assert http.post(f"{API}/fits/{fit_id}/link").status_code == 401
    link = http.post(f"{API}/fits/{fit_id}/link", headers=AUTH)
    assert link.status_code == 200 and link.json()["expires_at"] is None and not link.json()["draft"]


def test_uploads_are_kept_apart_from_saved_materials(http, brass):
    files = {"file": ("lab metal.csv", nk_csv(0.05), "text/csv")}
    upload = http.post(f"{API}/fits/upload", files=files, headers=AUTH)
    assert upload.status_code == 201, upload.text
    material_id = upload.json()["material_id"]
    default = listed(http)
    assert material_id not in [m["id"] for m in default] and {m["kind"] for m in default} == {"curves"}
    uploads = listed(http, kind="nk")
    assert [m["name"] for m in uploads if m["id"] == material_id] == ["lab metal"]
    both = http.get(f"{API}/materials", params=[("kind", "nk"), ("kind", "curves")]).json()["materials"]
    assert material_id in [m["id"] for m in both] and not [m for m in both if m["kind"] == "library"]
    library = http.get(f"{API}/materials", params={"kind": "library"}).json()
    ids = [m["id"] for m in library["materials"]]
    assert set(LIBRARY_NAMES) <= set(ids) and "Ti.Palm" in ids and library["next_cursor"] is None
    assert len(ids) == len({e["book"] for e in catalogue().values()})  # one preferred page per conductor
    assert http.get(f"{API}/materials", params={"kind": "bogus"}).status_code == 422
    # Search by name or source, the library's entries by symbol, name or source.
    found = http.get(f"{API}/materials", params={"q": "STUDIO"}).json()["materials"]
    assert [m["name"] for m in found] == ["studio brass"]
    gold = http.get(f"{API}/materials", params={"q": "gold", "kind": "library"}).json()["materials"]
    assert gold[0]["id"] == "Au" and gold[0]["name"] == "gold (Au)"
    assert {m["id"] for m in gold} == {e["id"] for e in search_catalogue("gold")}


def test_upload_min_coverage(http):
    short = {"file": ("short.csv", nk_csv(0.1, 380.0, 830.0), "text/csv")}  # 95.7% of 360-830 nm
    refused = http.post(f"{API}/fits/upload", files=short, data={"min_coverage": "0.99"}, headers=AUTH)
    assert refused.status_code == 422 and "min_coverage" in refused.json()["detail"]
    assert "95.7%" in refused.json()["detail"]
    low = http.post(f"{API}/fits/upload", files=short, data={"min_coverage": "0.5"}, headers=AUTH)
    assert low.status_code == 422 and "[0.9, 1]" in low.json()["detail"]
    accepted = http.post(f"{API}/fits/upload", files=short, data={"min_coverage": "0.95"}, headers=AUTH)
    assert accepted.status_code == 201, accepted.text
    assert accepted.json()["coverage"] == pytest.approx(450.0 / 470.0)


def test_library_to_browse(http):
    answer = http.get(f"{API}/library", params={"eta_i": 1.33}).json()
    assert answer["eta_i"] == 1.33 and [m["id"] for m in answer["materials"]] == list(catalogue())
    assert answer["total"] == len(answer["materials"]) >= 300 and set(LIBRARY_NAMES) <= set(catalogue())
    assert all(re.fullmatch(MATERIAL_ID_PATTERN, m["id"]) for m in answer["materials"])
    (gold,) = [m for m in answer["materials"] if m["id"] == "Au"]
    assert gold["name"] == "gold" and gold["symbol"] == "Au" and "Johnson" in gold["source"]
    assert gold["category"] == "metal" and gold["preferred"] and gold["label"].startswith("Johnson and Christy")
    assert gold["page_url"] == "https://refractiveindex.info/?shelf=main&book=Au&page=Johnson"
    assert gold["reference"].startswith("P. B. Johnson and R. W. Christy")
    lo, hi = gold["wavelength_range_nm"]
    assert lo < 360.0 and hi > 830.0 and gold["coverage"] == 1.0
    swatch = gold["swatch"]
    assert swatch["eta_i"] == 1.33 and swatch["angles_deg"][0] == 0.0
    assert len(swatch["srgb"]) == len(swatch["angles_deg"]) == len(swatch["acescg"])
    red, green, blue = (int(swatch["srgb"][0][i : i + 2], 16) for i in (1, 3, 5))
    assert red > green > blue  # gold is yellow at normal incidence
    air = http.get(f"{API}/library", params={"eta_i": 1.0, "q": "gold", "limit": 1}).json()
    assert [m["id"] for m in air["materials"]] == ["Au"] and air["total"] > 30
    assert air["materials"][0]["swatch"]["srgb"] != swatch["srgb"]
    # Names and symbols rank first; the citation is never searched.
    assert http.get(f"{API}/library", params={"q": "johnson christy"}).json()["materials"] == []
    first = {
        q: http.get(f"{API}/library", params={"q": q, "limit": 1}).json()["materials"][0]["id"]
        for q in ("brass", "TiN", "aluminum")
    }
    assert first == {"brass": "CuZn", "TiN": catalogue()[first["TiN"]]["id"], "aluminum": "Al"}
    assert catalogue()[first["TiN"]]["book"] == "TiN"
    nothing = http.get(f"{API}/library", params={"q": "unobtainium"}).json()
    assert nothing["materials"] == [] and nothing["suggestions"] == []
    # A query that matches nothing is answered with what it may have meant, swatches and all.
    near = http.get(f"{API}/library", params={"q": "stainless steel 316", "eta_i": 1.33}).json()
    assert near["materials"] == [] and near["total"] == 0
    assert [m["id"] for m in near["suggestions"]] == [
        "stainless-steel.Karlsson-austenitic",
        "stainless-steel.Karlsson-ferritic",
    ]
    assert near["suggestions"][0]["swatch"]["eta_i"] == 1.33 and len(near["suggestions"][0]["swatch"]["srgb"]) == 4
    assert [m["id"] for m in http.get(f"{API}/library", params={"q": "titanum"}).json()["suggestions"]] == ["Ti.Palm"]
    assert air["suggestions"] == []  # a query that matches has none
    assert http.get(f"{API}/library", params={"eta_i": 0.5}).status_code == 422
    presets = http.get(f"{API}/coat-presets").json()["presets"]
    assert [(p["id"], p["eta_i"]) for p in presets] == [(key, eta) for key, _, eta, _ in COAT_PRESETS]
    water = [p for p in presets if p["id"] == "water"][0]
    assert water["eta_i"] == 1.333 and "589 nm" in water["source"]
