"""``POST /api/v1/fits/upload`` chooses the model kind as ``POST /api/v1/fits`` does (``model``)."""

from __future__ import annotations

import pytest
from test_api import API, csv_text, gold_like_nk

pytestmark = pytest.mark.slow  # an app with its fitting pool


def test_an_upload_fits_the_kind_it_asks_for(client):
    content = csv_text(gold_like_nk(0.02))
    default = client.post(f"{API}/fits/upload", files={"file": ("metal.csv", content)})
    rgb = client.post(f"{API}/fits/upload", files={"file": ("metal.csv", content)}, data={"model": "rgb-conductor"})
    assert default.status_code == 201 and rgb.status_code == 201, (default.text[:200], rgb.text[:200])
    assert default.json()["model"] == "coated-conductor" and rgb.json()["model"] == "rgb-conductor"
    assert set(rgb.json()["coefficients"]) == {"n", "k"} and default.json()["id"] != rgb.json()["id"]
    refused = client.post(f"{API}/fits/upload", files={"file": ("metal.csv", content)}, data={"model": "schlick"})
    assert refused.status_code == 422 and "model" in refused.text
