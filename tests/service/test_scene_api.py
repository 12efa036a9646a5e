"""``POST /api/v1/scenes`` (service/api/routes/scenes.py): every status code it answers."""

import base64

import pytest

from fitting.models.pack import decode_pack, pack_from_json
from fitting.optics.library import library_material
from conftest import app_client

API = "/api/v1"
SCENE = {
    "name": "desk",
    "materials": [
        {"material": "Cu", "eta_i": 1.5},
        {"material": "Al", "name": "lamp", "eta_i": [1.0, 1.5]},
    ],
}


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    """One app with one worker, the scene fitted once."""
    with app_client(tmp_path_factory.mktemp("scenes"), metrics_samples=30) as client:
        response = client.post(f"{API}/scenes", json=SCENE)
        assert response.status_code == 200, response.text
        yield client, response.json()


@pytest.mark.slow  # its shared fixture's fits start the fitting pool's processes
class TestScenePack:
    @pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
    def test_report_and_pack(self, shared):
        _, body = shared
        assert body["scene"] == "desk"
        assert [m["name"] for m in body["materials"]] == ["Cu", "lamp"]
        assert body["materials"][1]["material"] == "Al"
        cu = body["materials"][0]
        # One eta_i: the rgb-conductor (6 halves) beats degree 0 and the general fit on both figures.
        assert cu["model"] == "rgb-conductor" and cu["coefficients"] == 6
        assert cu["shader_variant"] == "rgb_conductor" and cu["choice"]["model"] == cu["model"]
        assert cu["delta_E_2000"]["max"] <= cu["general"]["delta_E_2000"]["max"]
        assert cu["general"]["coefficients"] == 27
        assert cu["delta_E_2000"]["mean"] < cu["general"]["delta_E_2000"]["mean"]
        totals = body["totals"]
        assert totals["pack_bytes"] < totals["general_pack_bytes"]
        binary = base64.b64decode(body["pack_base64"])
        assert len(binary) == totals["pack_bytes"]
        packed = decode_pack(binary)
        assert [m.name for m in packed] == ["Cu", "lamp"]
        assert pack_from_json(__import__("json").dumps(body["pack"])) == packed

    @pytest.mark.slow  # starts a process or GL context
    def test_inline_nk_matches_the_library(self, shared):
        client, body = shared
        Cu = library_material("Cu")
        inline = {
            "materials": [
                {
                    "name": "Cu",
                    "eta_i": 1.5,
                    "source": Cu.source,
                    "nk": {"wavelength_nm": Cu.wavelength_nm.tolist(), "n": Cu.n.tolist(), "k": Cu.k.tolist()},
                }
            ]
        }
        response = client.post(f"{API}/scenes", json=inline)
        assert response.status_code == 200, response.text
        assert response.json()["pack"]["materials"][0]["coefficients"] == body["pack"]["materials"][0]["coefficients"]

    @pytest.mark.slow  # starts a process or GL context
    def test_saved_material_by_id(self, shared):
        client, _ = shared
        Cu = library_material("Cu")
        nk = {"wavelength_nm": Cu.wavelength_nm.tolist(), "n": Cu.n.tolist(), "k": (Cu.k * 0.9).tolist()}
        fit = client.post(f"{API}/fits", json={"name": "dull copper", "nk": nk})
        assert fit.status_code == 201, fit.text
        material_id = fit.json()["material_id"]
        response = client.post(f"{API}/scenes", json={"materials": [{"material": material_id, "eta_i": 1.2}]})
        assert response.status_code == 200, response.text
        assert response.json()["materials"][0]["material"] == material_id


class TestRefusals:
    @pytest.mark.parametrize(
        "body, fragment",
        [
            ({"materials": []}, "materials"),
            ({"materials": [{"material": "Au", "eta_i": 0.5}]}, "eta_i"),
            ({"materials": [{"material": "Au", "eta_i": {"min": 2.0, "max": 1.5}}]}, "min <= max"),
            ({"materials": [{"material": "Au"}]}, "eta_i"),
            (
                {
                    "materials": [
                        {"material": "Au", "nk": {"wavelength_nm": [400, 700], "n": [1, 1], "k": [0, 0]}, "eta_i": 1}
                    ]
                },
                "exactly one of",
            ),
            ({"materials": [{"material": "Unobtainium", "eta_i": 1}]}, "library conductor"),
            ({"materials": [{"material": "Au", "eta_i": 1}, {"material": "Au", "eta_i": 2}]}, "used twice"),
            (
                {
                    "materials": [
                        {"name": "x", "eta_i": 1.5, "nk": {"wavelength_nm": [500, 600], "n": [1, 1], "k": [1, 1]}}
                    ]
                },
                "must cover at least 90%",
            ),
            ({"materials": [{"material": "Au", "eta_i": 1}], "colour": "red"}, "colour"),
        ],
    )
    def test_422_names_the_field(self, shared, body, fragment):
        client, _ = shared
        response = client.post(f"{API}/scenes", json=body)
        assert response.status_code == 422, response.text
        assert fragment in response.text

    def test_401_without_token(self, tmp_path):
        with app_client(tmp_path, require_token=True, api_token="s3cret") as client:
            assert client.post(f"{API}/scenes", json=SCENE).status_code == 401

    def test_413_body_too_large(self, tmp_path):
        with app_client(tmp_path, max_body_bytes=2000) as client:
            nk = {"wavelength_nm": list(range(1, 500)), "n": [1.0] * 499, "k": [1.0] * 499}
            response = client.post(f"{API}/scenes", json={"materials": [{"name": "x", "nk": nk, "eta_i": 1}]})
            assert response.status_code == 413

    def test_503_when_the_pool_is_full(self, tmp_path):
        with app_client(tmp_path, fit_queue=0) as client:
            runner = client.app.state.runner
            runner._in_flight = runner.max_in_flight  # every slot taken
            try:
                response = client.post(f"{API}/scenes", json=SCENE)
            finally:
                runner._in_flight = 0
            assert response.status_code == 503 and int(response.headers["retry-after"]) >= 1

    @pytest.mark.slow  # 3.0 s (all cases 3.0 s) in a --durations=0 run
    def test_504_past_the_time_limit(self, tmp_path):
        # Its three parts' estimate (0.09 s) fits the limit; fitting them takes longer.
        with app_client(tmp_path, fit_timeout_s=0.1) as client:
            response = client.post(f"{API}/scenes", json=SCENE)
            assert response.status_code == 504
            assert "time limit" in response.json()["detail"]
