"""
Drafts and targets of curve fits: ``POST /fits/from-curves`` with ``draft``
stores the fit (reachable by id) without saving it under its name; the same
request without ``draft`` saves it (same id). ``GET /fits/{id}/curves``
returns, beside ``model``, the ``target`` the fit was fitted to at that
eta_i: the blended edited target for a curve fit, the reference otherwise.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import app_client

from fitting import curve_base_from_nk, edited_target, library_material
from fitting.fits.curves_input import RGBCurve

ANGLE = np.linspace(0.0, 90.0, 31)
MU = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("drafts"), metrics_samples=30) as client:
        yield client


def body(name, draft):
    base = curve_base_from_nk(library_material("Au"))
    rgb = base.rgb(MU, 1.5)
    rgb[:, 0] *= 0.9
    return {
        "name": name,
        "base": {"material": "Au"},
        "draft": draft,
        "curves": [{"eta_i": 1.5, "angle_deg": ANGLE.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}],
    }


def saved_names(client):
    return [m["name"] for m in client.get("/api/v1/materials").json()["materials"] if m["kind"] == "curves"]


@pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
def test_a_draft_is_not_saved_until_saved(shared):
    draft = shared.post("/api/v1/fits/from-curves", json=body("Draft gold", True))
    assert draft.status_code == 201, draft.text
    fit_id = draft.json()["id"]
    assert shared.get(f"/api/v1/fits/{fit_id}").status_code == 200
    assert "Draft gold" not in saved_names(shared)
    again = shared.post("/api/v1/fits/from-curves", json=body("Draft gold", True))
    assert again.status_code == 200 and "Draft gold" not in saved_names(shared)
    saved = shared.post("/api/v1/fits/from-curves", json=body("Draft gold", False))
    assert saved.status_code == 200 and saved.json()["id"] == fit_id
    assert saved_names(shared).count("Draft gold") == 1
    material = shared.get(f"/api/v1/materials/{saved.json()['material_id']}").json()
    assert material["latest_fit"]["id"] == fit_id


@pytest.mark.slow  # starts a process or GL context
def test_curves_return_the_blended_target(shared):
    fit = shared.post("/api/v1/fits/from-curves", json=body("Target gold", True)).json()
    base = curve_base_from_nk(library_material("Au"), (1.0, 2.5))
    request = body("Target gold", True)["curves"][0]
    curve = RGBCurve.from_angles(1.5, request["angle_deg"], request["rgb"])
    for eta_i in (1.5, 1.8, 2.3):
        answer = shared.get(f"/api/v1/fits/{fit['id']}/curves?eta_i={eta_i}&samples=19").json()
        mu = np.asarray(answer["cos_theta"])
        expected = edited_target(base, [curve], mu, np.full_like(mu, eta_i), 0.5)
        np.testing.assert_allclose(answer["target"], expected, atol=1e-9)  # the same
        # blend on JSON-exact inputs (a few u64); 1e-9 is a loose rounding bound
    # Beyond the blend width (0.5) the target is the base again.
    far = shared.get(f"/api/v1/fits/{fit['id']}/curves?eta_i=2.3&samples=19").json()
    np.testing.assert_allclose(
        far["target"], np.clip(base.rgb(np.asarray(far["cos_theta"]), 2.3), 0, 1), atol=1e-9
    )  # as above
    # A fit of n, k: the target is its reference.
    gold = shared.post("/api/v1/fits", json={"material": "Au"}).json()
    answer = shared.get(f"/api/v1/fits/{gold['id']}/curves?eta_i=1.5&samples=19").json()
    assert answer["target"] == answer["reference"]
