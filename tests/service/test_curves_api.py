"""Tests of ``POST /api/v1/fits/from-curves`` and ``GET /api/v1/fits/{id}/error-map``."""

from __future__ import annotations

import numpy as np
import pytest

from fitting.fits.curves_base import curve_base_from_nk
from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import decode_pack
from fitting.optics.library import library_material
from conftest import app_client

ANGLE = np.linspace(0.0, 90.0, 31)
URL = "/api/v1/fits/from-curves"


def gold_curve(eta_i=1.5, red_scale=1.0):
    mu = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))
    rgb = curve_base_from_nk(library_material("Au")).rgb(mu, eta_i)
    rgb[:, 0] *= 1.0 - (1.0 - red_scale) * (1.0 - (ANGLE / 90.0) ** 4)
    return {"eta_i": eta_i, "angle_deg": ANGLE.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("curves"), metrics_samples=30) as client:
        yield client


@pytest.fixture(scope="module")
def edited(shared):
    body = {"name": "pale gold", "base": {"material": "Au"}, "curves": [gold_curve(red_scale=0.85)]}
    response = shared.post(URL, json=body)
    assert response.status_code == 201, response.text
    return body, response.json()


@pytest.mark.slow  # its shared fixture's fits start the fitting pool's processes
class TestFromCurves:
    @pytest.mark.slow  # 2.8 s (all cases 2.8 s) in a --durations=0 run
    def test_answers_like_a_fit(self, edited):
        _, fit = edited
        assert fit["kind"] == "curves" and fit["name"] == "pale gold" and fit["degree"] == 2
        assert fit["library_material"] == "Au" and fit["has_nk"]
        assert len(fit["coefficients"]["F0"]) == 3
        model = fit["metrics"]["model"]
        assert 0.0 <= model["delta_E_mean"] <= model["delta_E_max"] < 10.0
        assert fit["metrics"]["details"]["target"]["delta_E_mean"] >= 0.0
        assert fit["timings"]["fit"] > 0.0

    @pytest.mark.slow  # starts a process or GL context
    def test_metrics_are_against_the_curves(self, shared, edited):
        body, fit = edited
        pack = shared.get(f"/api/v1/fits/{fit['id']}/pack?format=binary")
        (material,) = decode_pack(pack.content)
        curve = body["curves"][0]
        mu = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))
        model = coated_conductor_model(mu, 1.5, material.coefficients, material.eta_i_range)
        from fitting.colour.delta_e import delta_E_map

        dE = delta_E_map(np.array(curve["rgb"]), model)
        # The service's own score of the same float16 model against the same
        # (JSON-exact) curve, in float64: ~1e-12 per sample (Delta E ~1e4 per
        # unit RGB near black times a few u64); rel=1e-6 is a loose rounding bound.
        assert fit["metrics"]["model"]["delta_E_mean"] == pytest.approx(dE.mean(), rel=1e-6)
        assert fit["metrics"]["model"]["delta_E_max"] == pytest.approx(dE.max(), rel=1e-6)

    @pytest.mark.slow  # starts a process or GL context
    def test_same_request_served_from_store(self, shared, edited):
        body, fit = edited
        again = shared.post(URL, json=body)
        assert again.status_code == 200 and again.json()["id"] == fit["id"]
        assert again.headers["location"] == f"/api/v1/fits/{fit['id']}"

    def test_listed_as_a_saved_material(self, shared, edited):
        _, fit = edited
        listed = shared.get("/api/v1/materials").json()["materials"]
        mine = [m for m in listed if m["name"] == "pale gold"]
        assert len(mine) == 1 and mine[0]["kind"] == "curves"
        assert mine[0]["latest_fit_id"] == fit["id"]

    def test_undo_then_save_makes_the_earlier_state_latest(self, shared):
        body_a = {"name": "undo test", "base": {"material": "Au"}, "curves": [gold_curve(red_scale=0.9)]}
        body_b = {"name": "undo test", "base": {"material": "Au"}, "curves": [gold_curve(red_scale=0.7)]}
        a = shared.post(URL, json=body_a).json()
        b = shared.post(URL, json=body_b).json()
        assert a["material_id"] == b["material_id"] and a["id"] != b["id"]
        again = shared.post(URL, json=body_a)
        assert again.status_code == 200 and again.json()["id"] == a["id"]
        material = shared.get(f"/api/v1/materials/{a['material_id']}").json()
        assert material["latest_fit_id"] == a["id"]
        listed = [m for m in shared.get("/api/v1/materials").json()["materials"] if m["name"] == "undo test"]
        assert [m["latest_fit_id"] for m in listed] == [a["id"]]

    def test_an_edited_base_keeps_its_edits(self, shared):
        # X: Au with red pulled down at eta_i 1; then X edited at eta_i 2.5 only.
        low = gold_curve(eta_i=1.0, red_scale=0.4)
        x = shared.post(URL, json={"name": "red down", "base": {"material": "Au"}, "curves": [low]}).json()
        y = shared.post(URL, json={"name": "red down", "base": {"fit": x["id"]}, "curves": [gold_curve(eta_i=2.5)]})
        assert y.status_code == 201, y.text
        y = y.json()
        assert y["base_fit_id"] == x["id"] and y["library_material"] == "Au"

        def red_at_normal(fit):
            (m,) = decode_pack(shared.get(f"/api/v1/fits/{fit['id']}/pack?format=binary").content)
            return coated_conductor_model(1.0, 1.0, m.coefficients, m.eta_i_range)[0]

        gold = red_at_normal(shared.post("/api/v1/fits", json={"material": "Au"}).json())
        assert red_at_normal(x) < gold - 0.3
        assert red_at_normal(y) == pytest.approx(red_at_normal(x), abs=0.03)  # a
        # fit-quality claim (a refit keeps the edit), not precision

    def test_downloads(self, shared, edited):
        _, fit = edited
        for fmt in ("json", "glsl", "hlsl"):
            response = shared.get(f"/api/v1/fits/{fit['id']}/pack?format={fmt}")
            assert response.status_code == 200 and "pale gold" in response.text

    def test_base_fit_and_its_domain(self, shared, edited):
        _, fit = edited
        body = {"name": "paler gold", "base": {"fit": fit["id"]}, "curves": [gold_curve(2.0, 0.8)]}
        response = shared.post(URL, json=body)
        assert response.status_code == 201, response.text
        assert response.json()["base_fit_id"] == fit["id"]
        body["eta_i_range"] = [1.0, 2.0]
        refused = shared.post(URL, json=body)
        assert refused.status_code == 422 and "base fit's domain [1, 2.5]" in refused.json()["detail"]

    @pytest.mark.parametrize("etas, degree", [((1.5,), 0), ((1.2, 2.2), 1), ((1.0, 1.6, 2.5), 2)])
    def test_without_base_degree_from_curves(self, shared, etas, degree):
        body = {"name": f"from {len(etas)}", "curves": [gold_curve(e) for e in etas]}
        response = shared.post(URL, json=body)
        assert response.status_code == 201, response.text
        assert response.json()["degree"] == degree and not response.json()["has_nk"]

    def test_unknown_base_fit_404(self, shared):
        body = {"base": {"fit": "0" * 32}, "curves": [gold_curve()]}
        response = shared.post(URL, json=body)
        assert response.status_code == 404 and "is not a stored fit" in response.json()["detail"]

    @pytest.mark.parametrize(
        "change, needle",
        [
            (
                lambda b: b["curves"][0]["rgb"][3].__setitem__(0, 1.2),
                "`curves[0].rgb[3][0]` (body): Input should be less than or equal to 1",
            ),
            (
                lambda b: b["curves"][0]["rgb"][5].__setitem__(2, -0.1),
                "`curves[0].rgb[5][2]` (body): Input should be greater than or equal to 0",
            ),
            (
                lambda b: b["curves"][0].update(angle_deg=ANGLE[:4].tolist(), rgb=b["curves"][0]["rgb"][:4]),
                "at least 5 items",
            ),
            (lambda b: b["curves"][0].update(cos_theta=[0.5] * 31), "exactly one of `cos_theta` or `angle_deg`"),
            (
                lambda b: b["curves"][0].update(angle_deg=None, cos_theta=[1.5] * 31),
                "`curves[0].cos_theta[0]` (body): Input should be less than or equal to 1",
            ),
            (lambda b: b["curves"][0].update(eta_i=2.8), "`curves[0].eta_i` must lie in the domain [1, 2.5], got 2.8"),
            (lambda b: b["curves"].append(b["curves"][0]), "`curves[1].eta_i` must differ from `curves[0].eta_i`"),
            (lambda b: b.update(base={"material": "Au", "fit": "0" * 32}), "exactly one of `material`, `fit` or `nk`"),
            (lambda b: b.update(base={"material": "Unobtainium"}), "`base.material` (body)"),
            (lambda b: b.update(curves=[]), "`curves` (body): List should have at least 1 item"),
            (lambda b: b.update(blend_width=0), "`blend_width` (body): Input should be greater than 0"),
        ],
    )
    def test_bad_input_422_names_the_place(self, shared, change, needle):
        body = {"name": "bad", "base": {"material": "Au"}, "curves": [gold_curve()]}
        change(body)
        response = shared.post(URL, json=body)
        assert response.status_code == 422, response.text
        assert needle in response.json()["detail"]

    def test_repeated_cos_theta_422(self, shared):
        curve = {"eta_i": 1.5, "cos_theta": [0.1, 0.1, 0.4, 0.7, 1.0], "rgb": [[0.5, 0.5, 0.5]] * 5}
        response = shared.post(URL, json={"curves": [curve]})
        assert response.status_code == 422
        assert "`curves[0].cos_theta` must not repeat a value, got 0.1 twice" in response.json()["detail"]

    def test_nan_is_refused(self, shared):
        text = '{"curves": [{"eta_i": 1.5, "cos_theta": [0, 0.2, 0.4, NaN, 1], "rgb": [[0.5,0.5,0.5],[0.5,0.5,0.5],[0.5,0.5,0.5],[0.5,0.5,0.5],[0.5,0.5,0.5]]}]}'
        response = shared.post(URL, content=text, headers={"content-type": "application/json"})
        assert response.status_code == 422

    def test_token_required_401(self, tmp_path):
        with app_client(tmp_path, require_token=True, api_token="secret") as client:
            response = client.post(URL, json={"curves": [gold_curve()]})
            assert response.status_code == 401 and "Authorization: Bearer" in response.json()["detail"]

    def test_body_too_large_413(self, shared):
        import json

        text = json.dumps({"curves": [gold_curve()]}) + " " * 1_100_000  # past COATED_MAX_BODY_BYTES
        response = shared.post(URL, content=text, headers={"content-type": "application/json"})
        assert response.status_code == 413 and "COATED_MAX_BODY_BYTES" in response.json()["detail"]


class TestErrorMap:
    def test_curve_fit_against_edited_target(self, shared, edited):
        _, fit = edited
        response = shared.get(f"/api/v1/fits/{fit['id']}/error-map?angles=19&rows=7")
        assert response.status_code == 200
        body = response.json()
        assert body["against"] == "edited target"
        dE = np.array(body["delta_E"])
        assert dE.shape == (7, 19) and np.all(dE >= 0)
        assert body["delta_E_max"] == pytest.approx(dE.max(), abs=1e-4)  # the same
        # numbers through JSON; should the map travel in float32, u32 x Delta E
        # <= 100 = 6e-6: a rounding bound with room
        # The row at the edited eta_i (1.5) is scored against the edited curve itself.
        assert body["eta_i"][2] == 1.5

    def test_curves_only_rows_at_their_eta(self, shared):
        fit = shared.post(URL, json={"name": "two rows", "curves": [gold_curve(1.2), gold_curve(2.2)]}).json()
        body = shared.get(f"/api/v1/fits/{fit['id']}/error-map").json()
        assert body["against"] == "curves" and body["eta_i"] == [1.2, 2.2]

    def test_library_fit_against_reference(self, shared):
        fit = shared.post("/api/v1/fits", params={"metrics": "full"}, json={"material": "Cu"}).json()
        body = shared.get(f"/api/v1/fits/{fit['id']}/error-map?rows=5").json()
        assert body["against"] == "reference"
        # The service's own metrics (1 nm, 30 x 30) and the map (5 nm) agree closely.
        assert body["delta_E_mean"] == pytest.approx(fit["metrics"]["model"]["delta_E_mean"], abs=0.1)  # two
        # grids and spectral steps: a discretisation difference, not rounding

    def test_unknown_404_bad_query_422(self, shared):
        assert shared.get(f"/api/v1/fits/{'0' * 32}/error-map").status_code == 404
        assert shared.get(f"/api/v1/fits/{'0' * 32}/error-map?angles=1").status_code == 422
        assert shared.get("/api/v1/fits/nothex/error-map").status_code == 422
