"""``POST /api/v1/scenes`` with ``max_delta_e`` or ``prefer``: the chosen kinds, the reasons, 422s."""

from __future__ import annotations

import base64

import pytest

from conftest import app_client
from fitting.models.pack import decode_pack

# Its module-scoped `client` fits (the fitting pool's processes) or renders (GL).
pytestmark = pytest.mark.slow

API = "/api/v1"


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("scenekinds"), metrics_samples=30) as test_client:
        yield test_client


@pytest.mark.slow  # 2.9 s (all cases 2.9 s) in a --durations=0 run
def test_max_delta_e_chooses_per_material(client):
    response = client.post(
        f"{API}/scenes",
        json={
            "name": "ring",
            "max_delta_e": 0.05,
            "materials": [{"material": "Au", "eta_i": 1.5}, {"material": "Ag", "name": "band", "eta_i": 1.2}],
        },
    )
    assert response.status_code == 200, response.text
    body = response.json()
    au, band = body["materials"]
    assert au["model"] == "rgb-conductor" and "cheaper candidates miss it" in au["choice"]["reason"]
    assert band["material"] == "Ag" and band["delta_E_2000"]["mean"] <= 0.05
    models = [m.model for m in decode_pack(base64.b64decode(body["pack_base64"]))]
    assert models == [au["model"], band["model"]]
    assert body["pack"]["materials"][0]["model"] == "rgb-conductor"


@pytest.mark.slow  # starts a process or GL context
def test_prefer_accuracy(client):
    response = client.post(
        f"{API}/scenes", json={"prefer": "accuracy", "materials": [{"material": "Cu", "eta_i": 1.33}]}
    )
    assert response.status_code == 200, response.text
    (cu,) = response.json()["materials"]
    assert cu["choice"]["rule"] == "prefer accuracy"


@pytest.mark.parametrize(
    "extra, message",
    [
        ({"max_delta_e": 0}, "max_delta_e"),
        ({"max_delta_e": -1}, "max_delta_e"),
        ({"prefer": "speed"}, "prefer"),
        ({"max_delta_e": 0.1, "prefer": "accuracy"}, "at most one of `max_delta_e` and `prefer`"),
    ],
)
def test_bad_options_are_422(client, extra, message):
    response = client.post(f"{API}/scenes", json={"materials": [{"material": "Au", "eta_i": 1.5}], **extra})
    assert response.status_code == 422
    assert message in response.text
