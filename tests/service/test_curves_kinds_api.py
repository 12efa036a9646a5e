"""``POST /api/v1/fits/from-curves`` with ``"model": "rgb-conductor"``."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import app_client
from fitting.fits.curves_base import curve_base_from_nk
from fitting.models.pack import decode_pack
from fitting.models.rgb_conductor import rgb_conductor_model
from fitting.optics.library import library_material

# Its module-scoped `client` fits (the fitting pool's processes) or renders (GL).
pytestmark = pytest.mark.slow

URL = "/api/v1/fits/from-curves"
ANGLE = np.linspace(0.0, 90.0, 19)


def copper_curve(eta_i=1.5, blue=1.0):
    mu = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))
    rgb = curve_base_from_nk(library_material("Cu")).rgb(mu, eta_i)
    rgb[:, 2] *= blue
    return {"eta_i": eta_i, "angle_deg": ANGLE.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("curves-kinds"), metrics_samples=30) as client:
        yield client


@pytest.fixture(scope="module")
def rgb_fit(client):
    body = {
        "name": "cool copper",
        "base": {"material": "Cu"},
        "curves": [copper_curve(blue=1.1)],
        "model": "rgb-conductor",
    }
    response = client.post(URL, json=body)
    assert response.status_code == 201, response.text
    return body, response.json()


@pytest.mark.slow  # its shared fixture's fits start the fitting pool's processes
class TestCurveFitKinds:
    @pytest.mark.slow  # 2.8 s (all cases 2.8 s) in a --durations=0 run
    def test_answer_is_an_rgb_conductor(self, rgb_fit):
        _, fit = rgb_fit
        assert fit["model"] == "rgb-conductor"
        assert set(fit["coefficients"]) == {"n", "k"}
        assert all(len(fit["coefficients"][key]) == 3 for key in ("n", "k"))

    @pytest.mark.slow  # starts a process or GL context
    def test_kind_is_part_of_the_id(self, client, rgb_fit):
        body, fit = rgb_fit
        coated = client.post(URL, json={**body, "model": "coated-conductor"})
        assert coated.status_code == 201, coated.text
        assert coated.json()["id"] != fit["id"] and coated.json()["model"] == "coated-conductor"
        again = client.post(URL, json=body)
        assert again.status_code == 200 and again.json()["id"] == fit["id"]

    @pytest.mark.slow  # starts a process or GL context
    def test_curves_route_and_pack_are_the_kinds_model(self, client, rgb_fit):
        _, fit = rgb_fit
        curves = client.get(f"/api/v1/fits/{fit['id']}/curves?eta_i=1.5&samples=10")
        assert curves.status_code == 200, curves.text
        view = curves.json()
        (packed,) = decode_pack(client.get(f"/api/v1/fits/{fit['id']}/pack?format=binary").content)
        assert packed.model == "rgb-conductor"
        expected = rgb_conductor_model(np.asarray(view["cos_theta"]), 1.5, packed.coefficients)
        assert np.allclose(view["model"], expected, atol=1e-6)  # the same float64
        # model; 1e-6 allows a float32 cos theta on the wire (u32 x slope <= 10)
        assert view["target"] is not None and len(view["target"]) == 10

    def test_edit_of_an_edited_rgb_conductor(self, client, rgb_fit):
        _, fit = rgb_fit
        body = {
            "name": "cool copper",
            "base": {"fit": fit["id"]},
            "curves": [copper_curve(2.0, blue=1.05)],
            "model": "rgb-conductor",
        }
        response = client.post(URL, json=body)
        assert response.status_code == 201, response.text
        error_map = client.get(f"/api/v1/fits/{response.json()['id']}/error-map?angles=10&rows=4")
        assert error_map.status_code == 200, error_map.text
        assert error_map.json()["against"] == "edited target"

    def test_unknown_kind_422(self, client):
        response = client.post(URL, json={"base": {"material": "Cu"}, "curves": [copper_curve()], "model": "rgb"})
        assert response.status_code == 422, response.text
        assert "model" in response.text and "rgb-conductor" in response.text
