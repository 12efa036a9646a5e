"""``POST /api/v1/fits`` with a metal given by F0 and F82 tint: an rgb-conductor of the inverted index."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import app_client
from fitting.exports.colour_space import lin_rec709_to_ACEScg
from fitting.models.pack import pack_from_json
from fitting.optics.edge_tint import F0_F82_from_nk

API = "/api/v1"
GOLD = {"name": "artist gold", "f0": [0.944, 0.776, 0.373], "f82": [0.93, 0.96, 0.99]}


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("colours"), metrics_samples=30) as client:
        yield client


@pytest.mark.slow  # the module's app starts its store and pools (about 9 s on a busy machine)
class TestFitFromColours:
    def test_fits_and_is_stored(self, client):
        response = client.post(f"{API}/fits", json={**GOLD, "space": "acescg"})
        assert response.status_code == 201, response.text
        fit = response.json()
        assert fit["model"] == "rgb-conductor" and fit["name"] == "artist gold"
        model = pack_from_json(client.get(f"{API}/fits/{fit['id']}/pack?format=json").text)[0]
        n, k = model.coefficients.astype(np.float64)
        # The float16 index gives back the colours (acescg: no conversion) to float16's precision.
        F0, tint = F0_F82_from_nk(n, k)
        np.testing.assert_allclose(F0, GOLD["f0"], atol=2e-3)
        np.testing.assert_allclose(tint, GOLD["f82"], atol=5e-3)
        again = client.post(f"{API}/fits", json={**GOLD, "space": "acescg"})
        assert again.status_code == 200 and again.json()["id"] == fit["id"]

    def test_rec709_colours_are_converted(self, client):
        response = client.post(f"{API}/fits", json={**GOLD, "name": "artist gold 709"})
        assert response.status_code == 201, response.text
        fit = response.json()
        model = pack_from_json(client.get(f"{API}/fits/{fit['id']}/pack?format=json").text)[0]
        F0, _ = F0_F82_from_nk(*model.coefficients.astype(np.float64))
        np.testing.assert_allclose(F0, np.clip(lin_rec709_to_ACEScg(GOLD["f0"]), 0, 1), atol=2e-3)

    def test_exports_like_any_fit(self, client):
        fit = client.post(f"{API}/fits", json={**GOLD, "name": "artist gold 709"}).json()
        response = client.get(f"{API}/fits/{fit['id']}/pack?format=openpbr&eta_i=1.5")
        assert response.status_code == 200 and b"open_pbr_surface" in response.content

    @pytest.mark.parametrize(
        "body, words",
        [
            ({"name": "x", "f0": [0.5, 0.5, 0.5]}, ["`f0` and `f82` together"]),
            ({"name": "x", "f0": [0.5, 0.5], "f82": [1, 1]}, ["f0", "at least 3"]),
            ({"name": "x", "f0": [0.5, 1.5, 0.5], "f82": [1, 1, 1]}, ["less than or equal to 1"]),
            ({"material": "Au", "f0": [0.5, 0.5, 0.5], "f82": [1, 1, 1]}, ["exactly one of"]),
            ({"name": "x", "f0": [0.5, 0.5, 0.5], "f82": [1, 1, 1], "space": "srgb"}, ["space", "'acescg'"]),
        ],
    )
    def test_bad_colours_422(self, client, body, words):
        response = client.post(f"{API}/fits", json=body)
        assert response.status_code == 422, response.text
        detail = json.dumps(response.json())
        for word in words:
            assert word in detail, detail


@pytest.mark.slow  # the module's app (see above)
class TestColourCurves:
    """``POST /api/v1/colour-curves``: the curves the editor's colour controls set."""

    BODY = {"f0": GOLD["f0"], "f82": GOLD["f82"], "eta_i": [1.0, 1.5, 2.5], "samples": 46}

    def test_in_air_the_curve_at_1_starts_at_the_colour(self, client):
        listed = client.get(f"{API}/materials").json()["materials"]
        response = client.post(f"{API}/colour-curves", json=self.BODY)
        assert response.status_code == 200, response.text
        answer = response.json()
        assert answer["theta_deg"] == list(np.linspace(0.0, 90.0, 46))
        assert [c["eta_i"] for c in answer["curves"]] == [1.0, 1.5, 2.5]
        F0 = lin_rec709_to_ACEScg(GOLD["f0"])
        rgb = [np.asarray(c["rgb"]) for c in answer["curves"]]
        np.testing.assert_allclose(rgb[0][0], F0, atol=1e-9)  # both anchors hold to rounding (edge_tint.py)
        np.testing.assert_allclose(rgb[0][-1], 1.0, atol=1e-12)  # grazing
        assert np.all(rgb[1][0] < rgb[0][0]), "the same metal under a coat reflects less at normal incidence"
        assert answer["reachable"] == [True, True, True] and len(answer["n"]) == len(answer["k"]) == 3
        # Nothing stored: the list of materials does not grow.
        assert client.get(f"{API}/materials").json()["materials"] == listed

    def test_under_the_coat_the_curve_at_its_index_starts_at_the_colour(self, client):
        answer = client.post(f"{API}/colour-curves", json={**self.BODY, "seen_at": 1.5}).json()
        np.testing.assert_allclose(answer["curves"][1]["rgb"][0], lin_rec709_to_ACEScg(GOLD["f0"]), atol=1e-9)
        air = client.post(f"{API}/colour-curves", json=self.BODY).json()
        np.testing.assert_allclose(np.asarray(answer["n"]), 1.5 * np.asarray(air["n"]), rtol=1e-12)

    @pytest.mark.parametrize(
        "change, words",
        [
            ({"eta_i": []}, ["eta_i", "at least 1"]),
            ({"eta_i": [1.5] * 17}, ["eta_i", "at most 16"]),
            ({"seen_at": 3.5}, ["seen_at", "less than or equal to 3"]),
            ({"samples": 1}, ["samples", "greater than or equal to 2"]),
            ({"f82": [0.5, -0.1, 0.5]}, ["f82", "greater than or equal to 0"]),
            ({"f0": None}, ["f0"]),
        ],
    )
    def test_bad_requests_422(self, client, change, words):
        response = client.post(f"{API}/colour-curves", json={**self.BODY, **change})
        assert response.status_code == 422, response.text
        detail = json.dumps(response.json())
        for word in words:
            assert word in detail, detail
