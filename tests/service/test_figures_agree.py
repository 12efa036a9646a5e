"""
One figure end to end: for the same saved fit, the API's
``metrics.figure``, the pack JSON's ``metrics.figure`` and the GLSL and HLSL
headers quote the same numbers, with the same words for what they are
measured against (the measured metal for an n, k fit, your edited curves
for a curve fit), and say where the max is.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fitting.fits.curves_base import curve_base_from_nk
from fitting.fits.metrics import AGAINST_CURVES, AGAINST_MEASURED, headline
from fitting.optics.library import library_material

from conftest import app_client

API = "/api/v1"
ANGLE = np.linspace(0.0, 90.0, 31)


def pale_gold_curve(eta_i=1.5):
    mu = np.where(ANGLE == 90.0, 0.0, np.cos(np.radians(ANGLE)))
    rgb = curve_base_from_nk(library_material("Au")).rgb(mu, eta_i)
    rgb[:, 0] *= 0.85
    return {"eta_i": eta_i, "angle_deg": ANGLE.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("figures"), metrics_samples=30) as active:
        yield active


@pytest.fixture(scope="module")
def fits(client):
    made = {}
    for label, url, body in (
        # `?metrics=full`: the answer waits for the fit's evaluation on the metrics grid.
        ("nk", f"{API}/fits?metrics=full", {"material": "Au"}),
        ("rgb-nk", f"{API}/fits?metrics=full", {"material": "Au", "model": "rgb-conductor"}),
        (
            "curves",
            f"{API}/fits/from-curves",
            {"name": "pale gold", "base": {"material": "Au"}, "curves": [pale_gold_curve()]},
        ),
        (
            "rgb-curves",
            f"{API}/fits/from-curves",
            {
                "name": "pale gold rgb",
                "base": {"material": "Au"},
                "curves": [pale_gold_curve()],
                "model": "rgb-conductor",
            },
        ),
    ):
        response = client.post(url, json=body)
        assert response.status_code == 201, response.text
        made[label] = response.json()
    return made


@pytest.mark.slow  # its fixture's fits start the fitting pool's processes
@pytest.mark.parametrize("label", ["nk", "rgb-nk", "curves", "rgb-curves"])
def test_api_pack_json_and_shader_headers_quote_one_figure(client, fits, label):
    fit = fits[label]
    figure = fit["metrics"]["figure"]
    against = AGAINST_CURVES if label.endswith("curves") else AGAINST_MEASURED
    assert figure["against"].startswith(against)
    assert 0.0 <= figure["delta_E_mean"] <= figure["delta_E_max"]
    assert 1.0 <= figure["max_at"]["eta_i"] <= 2.5 and 0.0 <= figure["max_at"]["theta_deg"] <= 90.0
    # The stored fit answers the same.
    assert client.get(f"{API}/fits/{fit['id']}").json()["metrics"]["figure"] == figure
    # The pack JSON carries the figure itself: the same numbers, exactly.
    pack = json.loads(client.get(f"{API}/fits/{fit['id']}/pack?format=json").content)
    assert pack["materials"][0]["metrics"]["figure"] == figure
    # The headers quote it in words, with the same rounding.
    words = headline({"figure": figure})
    assert f"mean {figure['delta_E_mean']:.3f}, max {figure['delta_E_max']:.3f}" in words
    for language in ("glsl", "hlsl"):
        text = client.get(f"{API}/fits/{fit['id']}/pack?format={language}").text
        assert words in text, (language, words)


@pytest.mark.slow
def test_a_curve_fits_figure_is_the_whole_target_the_editor_shows(fits):
    details = fits["curves"]["metrics"]["details"]
    figure = fits["curves"]["metrics"]["figure"]
    assert figure["delta_E_mean"] == details["target"]["delta_E_mean"]
    assert figure["delta_E_max"] == details["target"]["delta_E_max"]
    assert figure["max_at"] == {"eta_i": details["target"]["at_eta_i"], "theta_deg": details["target"]["at_theta_deg"]}


@pytest.mark.slow
@pytest.mark.parametrize("label", ["nk", "rgb-nk"])
def test_provenance_is_the_settings_that_ran(client, fits, label):
    """An n, k fit records its kind's settings (the rgb-conductor's 1 nm reference), not FitSettings()."""
    from dataclasses import asdict

    from fitting.fits.kinds import fit_kind

    fit = fits[label]
    record = client.app.state.store.get_fit(fit["id"])
    expected = asdict(fit_kind(fit["model"]).settings)
    assert record.provenance["settings"] == json.loads(json.dumps(expected))
    # timings["total"] is the whole fit (its evaluation on the metrics grid runs apart, later).
    assert record.timings["total"] >= record.timings["fit"] > 0.0 and "evaluate" not in record.timings
