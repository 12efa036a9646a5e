"""
A new model kind is one file: the toy kind of tests/toy_model_kind.py
(Schlick with a constant F0, 3 float16), loaded with
``COATED_PLUGINS=tests/toy_model_kind.py`` and changed nowhere else, is
fitted by the CLI (``fit --model toy-schlick``), by ``POST /api/v1/fits``
and ``/fits/from-curves``, packed by ``GET /fits/{id}/pack`` and
``POST /api/v1/packs``, listed with its parameters and preview GLSL by
``GET /api/v1/domain``, and opened and drawn by the editor's WebGL preview
in Chromium: every pixel of the model band's float read-back is numpy's
Schlick at the GL's own cosine, and its rough lobe has its albedo table
row from its own Fresnel (model_albedo_table.frag), against
fitting.shading.ibl.directional_albedo.

Tolerances: ``FRESNEL`` 2e-6, float32 Schlick against float64 at the same
float32 cosine ((1 - mu)^5 in 4 products and 3 more roundings of values
<= 1: 8 u32 = 4.8e-7, with room); ``TABLE`` 3e-4, the GGX quadrature under
SwiftShader's sin and cos (as tests/static/test_editor_rgb_conductor.py).
"""

from __future__ import annotations

import os
from pathlib import Path

import loopback
import numpy as np
import pytest
from conftest import run_command, server_process
from editor_pages import camera_rays, chromium, open_editor, pages, read_float  # noqa: F401 (fixtures)
from playwright.sync_api import expect

from fitting import curve_base_from_nk, library_material
from fitting.models.kinds import MODEL_KINDS
from fitting.models.pack import decode_pack
from fitting.shading.ibl import directional_albedo

pytestmark = [pytest.mark.server, pytest.mark.browser]

TESTS = Path(__file__).resolve().parents[1]
PLUGIN = {"COATED_PLUGINS": str(TESTS / "toy_model_kind.py")}
API = "/api/v1"
TOY = "toy-schlick"
W, H = 96, 64
NODES = 127
MU = (np.arange(NODES) / (NODES - 1)) ** 2
FRESNEL = 2.0e-6
TABLE = 3.0e-4
ANGLES = np.linspace(0.0, 90.0, 19)


def schlick(mu, F0):
    mu = np.clip(np.asarray(mu, dtype=np.float64), 0.0, 1.0)[..., None]
    return F0 + (1.0 - F0) * (1.0 - mu) ** 5


@pytest.fixture(scope="module")
def toy_server(tmp_path_factory):
    with server_process(tmp_path_factory.mktemp("toy-kind") / "data", **PLUGIN) as server:
        yield server


@pytest.fixture(scope="module")
def live_server(toy_server):
    """The editor's server for this module's browser test: the one with the toy kind."""
    return toy_server.url


@pytest.fixture(scope="module")
def gold(toy_server):
    with loopback.Client(base_url=toy_server.url, timeout=120) as http:
        answer = http.post(f"{API}/fits", json={"material": "Au", "model": TOY})
        assert answer.status_code in (200, 201), answer.text[:300]
        return answer.json()


def test_the_toy_is_registered_only_by_its_plugin():
    assert TOY not in MODEL_KINDS  # this process never loaded it


def test_the_cli_fits_the_toy(tmp_path):
    out = tmp_path / "au.bin"
    done = run_command(
        "fitting", "fit", "Au", "--model", TOY, "--no-metrics", "-o", str(out), env={**os.environ, **PLUGIN}
    )
    assert done.returncode == 0, done.stderr[-500:]
    refused = run_command("fitting", "fit", "Au", "--model", TOY)
    assert refused.returncode == 2 and f"invalid choice: '{TOY}'" in refused.stderr
    # This process has no toy kind: its pack reader refuses the toy's kind byte by name.
    with pytest.raises(ValueError, match="model kind code 200"):
        decode_pack(out.read_bytes())


def test_the_domain_lists_the_toy(toy_server):
    with loopback.Client(base_url=toy_server.url, timeout=60) as http:
        domain = http.get(f"{API}/domain").json()
    kinds = domain["model_kinds"]
    assert [k["name"] for k in kinds][:2] == ["coated-conductor", "rgb-conductor"] and kinds[-1]["name"] == TOY
    assert domain["default_model"] == "coated-conductor"
    toy = kinds[-1]
    assert (toy["parameters"], toy["max_degree"], toy["split_sum"]) == (["F0"], 0, False)
    assert '#include "cf_fresnel_baselines.glsl"' in toy["glsl"]
    assert "return cf_schlick(NdotV, vec3(unpackHalf2x16(words[0]), unpackHalf2x16(words[1]).x));" in toy["glsl"]


def test_rest_and_packs_serve_the_toy(toy_server, gold):
    assert gold["model"] == TOY and list(gold["coefficients"]) == ["F0"] and len(gold["coefficients"]["F0"]) == 3
    with loopback.Client(base_url=toy_server.url, timeout=120) as http:
        one = http.get(f"{API}/fits/{gold['id']}/pack", params={"format": "json"})
        assert one.status_code == 200, one.text[:300]
        assert one.json()["materials"][0]["model"] == TOY
        pack = http.post(f"{API}/packs", json={"fit_ids": [gold["id"]], "format": "json"})
        assert pack.status_code == 200, pack.text[:300]
        (material,) = pack.json()["materials"]
        assert material["model"] == TOY and material["coefficients"] == {"F0": gold["coefficients"]["F0"]}
        binary = http.post(f"{API}/packs", json={"fit_ids": [gold["id"]], "format": "binary"})
        assert binary.status_code == 200 and binary.content[:4] == b"CFPK", binary.content[:40]
        refused = http.post(f"{API}/fits", json={"material": "Au", "model": "toy-fresnel"})
        assert (
            refused.status_code == 422
            and f"'coated-conductor', 'rgb-conductor', '{TOY}', got 'toy-fresnel'" in refused.text
        )


@pytest.fixture(scope="module")
def toy_curve_fit(live_server):
    """A saved toy curve fit of gold with its blue raised."""
    mu = np.where(ANGLES == 90.0, 0.0, np.cos(np.radians(ANGLES)))
    rgb = curve_base_from_nk(library_material("Au")).rgb(mu, 1.5)
    rgb[:, 2] *= 1.1
    body = {
        "name": "cool toy gold",
        "base": {"material": "Au"},
        "model": TOY,
        "curves": [{"eta_i": 1.5, "angle_deg": ANGLES.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}],
    }
    response = loopback.post(f"{live_server}{API}/fits/from-curves", json=body, timeout=300)
    assert response.status_code == 201, response.text
    fit = response.json()
    assert fit["model"] == TOY
    return fit


def test_the_editor_draws_the_toy(pages, live_server, toy_curve_fit):
    fit = toy_curve_fit
    page = pages.new()
    open_editor(page, live_server + "/")
    page.select_option("#material", f"saved:{fit['material_id']}")
    expect(page.locator("#fit-id")).to_have_text(fit["id"])
    page.wait_for_function(
        "!document.body.hasAttribute('aria-busy')"
        " && document.getElementById('preview').dataset.fit === document.getElementById('fit-id').textContent"
    )
    assert page.text_content("#coefficients").startswith(TOY)
    assert page.get_attribute("#preview", "data-model") == TOY
    assert page.get_attribute("#preview", "data-program") == "mirror"
    page.select_option("#environment", "white_sky")
    page.select_option("#compare", "none")
    state = page.evaluate(
        "(() => { const s = window.cfPreview.state; return {orbit: s.orbit, fov: s.fov, eta: s.eta}; })()"
    )
    geometry, fresnel = read_float(page, "geometry", W, H), read_float(page, "fresnel", W, H)
    NdotV, hit, _, _ = camera_rays(*state["orbit"], state["fov"], W, H)
    model = (geometry[..., 1] > 0.5) & (geometry[..., 2] == 0)
    assert model.sum() > 0.25 * W * H and np.mean((geometry[..., 1] > 0.5) != hit) < 0.01
    F0 = np.asarray(fit["coefficients"]["F0"], dtype=np.float64)
    err = np.abs(fresnel[..., :3][model] - schlick(geometry[..., 0], F0)[model]).max()
    assert err < FRESNEL, err

    page.select_option("#environment", "studio")
    page.fill("#roughness", "0.45")
    page.dispatch_event("#roughness", "input")
    page.evaluate("window.cfPreview.ready()")
    page.wait_for_function("document.getElementById('preview').dataset.program === 'split-sum'")
    got = page.evaluate("window.cfPreview.readTables()")
    table = np.asarray(got["albedo"], dtype=np.float64).reshape(3, NODES, 4)[..., :3]
    expected = directional_albedo(MU, 0.45, lambda c: schlick(c, F0))
    table_err = np.abs(table[0] - expected).max()
    assert table_err < TABLE, table_err
    assert page.evaluate("window.cfPreview.gl.getError()") == 0
    print(f"toy kind: mirror max |GL - numpy| {err:.2e}, rough 0.45 table {table_err:.2e}")
