"""
Live refits: ``POST /fits/from-curves`` with ``live`` (a draft, one short
solve started from ``start_fit``) while a curve is dragged, and
``curves_eta_i``: the fit's curves in the same answer.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import app_client

from fitting import curve_base_from_nk, library_material

ANGLE = np.linspace(0.0, 90.0, 31)
MU = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))
ROUTE = "/api/v1/fits/from-curves"


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("live"), metrics_samples=30) as client:
        base = client.post("/api/v1/fits", json={"material": "Au", "eta_i_range": [1.0, 2.5]})
        assert base.status_code in (200, 201), base.text
        yield client, base.json()


def body(base_id, scale, **extra):
    rgb = curve_base_from_nk(library_material("Au")).rgb(MU, 1.5)
    rgb[:, 0] *= scale
    return {
        "name": "Live gold",
        "base": {"fit": base_id},
        "draft": True,
        "curves": [{"eta_i": 1.5, "angle_deg": ANGLE.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}],
        **extra,
    }


def saved_names(client):
    return [m["name"] for m in client.get("/api/v1/materials").json()["materials"] if m["kind"] == "curves"]


@pytest.mark.slow  # 3.1 s (all cases 3.1 s) in a --durations=0 run
def test_a_drag_of_live_refits_stays_in_range_and_is_never_saved(shared):
    client, base = shared
    start = base["id"]
    for scale in (0.97, 0.93, 0.88, 0.8, 0.7):
        answer = client.post(ROUTE, json=body(base["id"], scale, live=True, start_fit=start))
        assert answer.status_code == 201, answer.text
        fit = answer.json()
        target = fit["metrics"]["details"]["target"]
        # The [0, 1] constraint holds for live refits too, on the whole domain's scoring grid.
        assert -1e-4 <= target["model_min"] and target["model_max"] <= 1 + 1e-4
        assert np.isfinite(target["delta_E_mean"])
        start = fit["id"]
    assert "Live gold" not in saved_names(client)
    full = client.post(ROUTE, json=body(base["id"], 0.7))
    assert full.status_code == 201 and full.json()["id"] != start  # a full refit is its own fit
    # The full refit is at least as close to the whole target as the live one it replaces.
    live_error = client.get(f"/api/v1/fits/{start}").json()["metrics"]["details"]["target"]["delta_E_mean"]
    assert full.json()["metrics"]["details"]["target"]["delta_E_mean"] <= live_error + 1e-6


@pytest.mark.slow  # starts a process or GL context
def test_the_start_is_part_of_the_id(shared):
    client, base = shared
    first = client.post(ROUTE, json=body(base["id"], 0.9, live=True, start_fit=base["id"])).json()
    other = client.post(ROUTE, json=body(base["id"], 0.95, live=True, start_fit=base["id"])).json()
    again = client.post(ROUTE, json=body(base["id"], 0.9, live=True, start_fit=other["id"])).json()
    assert again["id"] != first["id"]
    same = client.post(ROUTE, json=body(base["id"], 0.9, live=True, start_fit=base["id"]))
    assert same.status_code == 200 and same.json()["id"] == first["id"]


@pytest.mark.slow  # its module fixture's fits start the fitting pool's processes
@pytest.mark.parametrize(
    "extra, status, needle",
    [
        ({"live": True, "draft": False}, 422, "`live` refits are drafts"),
        ({"start_fit": "0" * 32}, 422, "`start_fit` is for `live` refits only"),
        ({"live": True, "start_fit": "0" * 32}, 404, "`start_fit`"),
        ({"live": True, "start_fit": "nothex"}, 422, "start_fit"),
    ],
)
def test_bad_live_requests_name_the_field(shared, extra, status, needle):
    client, base = shared
    answer = client.post(ROUTE, json=body(base["id"], 0.9, **extra))
    assert answer.status_code == status, answer.text
    assert needle in answer.text


def test_start_fit_of_another_domain_is_refused(shared):
    client, base = shared
    other = client.post("/api/v1/fits", json={"material": "Au", "eta_i_range": [1.0, 2.0]}).json()
    answer = client.post(ROUTE, json=body(base["id"], 0.9, live=True, start_fit=other["id"]))
    assert answer.status_code == 422 and "`start_fit` must have the refit's domain" in answer.text


def test_curves_in_the_answer_equal_the_curves_route(shared):
    client, base = shared
    answer = client.post(f"{ROUTE}?curves_eta_i=1.8&curves_samples=37", json=body(base["id"], 0.85))
    assert answer.status_code in (200, 201), answer.text
    fit = answer.json()
    separate = client.get(f"/api/v1/fits/{fit['id']}/curves", params={"eta_i": 1.8, "samples": 37}).json()
    assert fit["curves"] == separate
    assert client.post(ROUTE, json=body(base["id"], 0.85)).json()["curves"] is None
    for query in ("curves_eta_i=0.5", "curves_eta_i=nan", "curves_eta_i=1.5&curves_samples=1"):
        refused = client.post(f"{ROUTE}?{query}", json=body(base["id"], 0.85))
        assert refused.status_code == 422, (query, refused.text)


def test_measured_curves_are_cached_and_exact():
    from fitting.colour.reference import reference_ACEScg
    from fitting.domain import cos_theta_from_angle
    from fitting.models.baselines import baseline_inputs, lazanyi_adjusted
    from service.jobs.nk import _measured_curves

    nk = library_material("Cu")
    mu = cos_theta_from_angle(np.linspace(0.0, 90.0, 19))
    first = _measured_curves(nk, 1.7, 19)
    inputs = baseline_inputs(nk)
    assert first[0] == reference_ACEScg(nk, mu, 1.7).tolist()
    assert first[1] == lazanyi_adjusted(mu, 1.7, inputs["F0_air"], inputs["F82_air"]).tolist()
    assert _measured_curves(nk, 1.7, 19) is first  # the same material, eta_i and angles: reused
    assert _measured_curves(nk, 1.8, 19)[0] != first[0]
