"""
``GET /api/v1/fits/{id}/reference-texture`` (the spectral reference of the
editor's real-time preview), the GLSL the editor loads from ``/glsl/`` and
the offline ``/docs`` (Swagger UI from npm swagger-ui-dist, scripts/swagger-ui/).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import app_client

from fitting import baseline_inputs, curve_base_from_nk, library_material


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("texture"), metrics_samples=30) as client:
        yield client


@pytest.fixture(scope="module")
def gold(shared):
    response = shared.post("/api/v1/fits", json={"material": "Au", "eta_i_range": [1.0, 2.5]})
    assert response.status_code in (200, 201), response.text
    return response.json()


@pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
def test_texture_is_the_reference_grid(shared, gold):
    response = shared.get(f"/api/v1/fits/{gold['id']}/reference-texture")
    assert response.status_code == 200, response.text
    assert response.headers["content-type"] == "application/octet-stream"
    width, height = int(response.headers["x-texture-width"]), int(response.headers["x-texture-height"])
    assert (width, height) == (257, 31)
    texture = np.frombuffer(response.content, dtype="<f4").reshape(height, width, 3)
    nk = library_material("Au")
    base = curve_base_from_nk(nk, (1.0, 2.5))
    # The texture is base.RGB rounded to float32: u32 = 6e-8 relative
    # (rtol 1e-6 = 17 u32; atol 1e-7 for values near 0).
    np.testing.assert_allclose(texture, base.RGB, rtol=1e-6, atol=1e-7)
    # Row j is eta_i = 1 + 0.05 j, column i is cos theta = i / 256.
    np.testing.assert_allclose(texture[10, 256], base.rgb(1.0, 1.5), rtol=1e-6)  # a node: float32, as above
    assert [float(v) for v in response.headers["x-eta-i-range"].split(",")] == [1.0, 2.5]
    inputs = baseline_inputs(nk)
    for header, key in (("x-f0-air", "F0_air"), ("x-f82-air", "F82_air")):
        np.testing.assert_allclose(
            [float(v) for v in response.headers[header].split(",")], inputs[key], rtol=1e-8
        )  # headers
        # print ~9 significant digits: within 5e-9 relative


@pytest.mark.slow  # starts a process or GL context
def test_texture_refusals(shared):
    curves = {
        "eta_i": 1.5,
        "angle_deg": [0, 30, 60, 80, 90],
        "rgb": [[0.9, 0.6, 0.3], [0.9, 0.6, 0.3], [0.9, 0.62, 0.35], [0.93, 0.8, 0.6], [1, 1, 1]],
    }
    fit = shared.post("/api/v1/fits/from-curves", json={"name": "no nk", "curves": [curves]})
    assert fit.status_code == 201, fit.text
    response = shared.get(f"/api/v1/fits/{fit.json()['id']}/reference-texture")
    assert response.status_code == 422
    assert "no n, k" in response.json()["detail"]
    assert shared.get(f"/api/v1/fits/{'0' * 32}/reference-texture").status_code == 404
    assert shared.get("/api/v1/fits/nothex/reference-texture").status_code == 422


def test_glsl_is_served_as_is(shared):
    from preview_shaders.gl import GLSL_DIR

    for name in ("shader_ball.frag", "cf_coated_conductor.glsl", "cf_reference_texture.glsl"):
        response = shared.get(f"/glsl/{name}")
        assert response.status_code == 200
        assert response.text == (GLSL_DIR / name).read_text()
    assert shared.get("/glsl/../service/main.py").status_code == 404


def test_docs_use_local_assets(shared):
    page = shared.get("/docs")
    assert page.status_code == 200
    assert "cdn" not in page.text.lower()
    assert "/vendor/swagger-ui/swagger-ui-bundle.js" in page.text
    script = shared.get("/vendor/swagger-ui/swagger-ui-bundle.js")
    assert script.status_code == 200 and len(script.content) > 100_000
    assert shared.get("/vendor/swagger-ui/swagger-ui.css").status_code == 200
    assert shared.get("/redoc").status_code == 404  # dropped: its page loads CDN scripts and fonts
