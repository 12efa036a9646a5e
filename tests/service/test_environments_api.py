"""
``GET /api/v1/environments/{environment}/prefiltered``: the preview
environments prefiltered per roughness for the editor's WebGL split sum,
the same slices as the server's own rough preview.
"""

from __future__ import annotations

import numpy as np
import pytest

import loopback
from conftest import app_client, server_process

# Its module-scoped `client` fits (the fitting pool's processes) or renders (GL).
pytestmark = pytest.mark.slow

API = "/api/v1"


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("environments")) as test_client:
        yield test_client


@pytest.mark.slow  # 3.4 s (all cases 3.4 s) in a --durations=0 run
@pytest.mark.gl
@pytest.mark.parametrize("environment", ["white_sky", "studio", "outdoor"])
def test_slices_are_the_rough_preview_s(client, environment):
    from preview_shaders.gl import RenderThread
    from preview_shaders.rough import ENVIRONMENTS, ROUGHNESS_NODES, prefiltered_environment

    response = client.get(f"{API}/environments/{environment}/prefiltered")
    assert response.status_code == 200, response.text
    assert response.headers["content-type"] == "application/octet-stream"
    layers, height, width = (int(response.headers[f"x-texture-{k}"]) for k in ("layers", "height", "width"))
    assert (layers, height, width) == (ROUGHNESS_NODES, 64, 128)
    data = np.frombuffer(response.content, "<f4").reshape(layers, height, width, 3)
    with RenderThread() as thread:  # drawn in a render process; the same slices here
        expected = prefiltered_environment(thread, ENVIRONMENTS.index(environment))
    np.testing.assert_array_equal(data, expected)
    if environment == "white_sky":
        np.testing.assert_array_equal(data, 1.0)
    else:
        # Lit unevenly; the blur of the roughest slice narrows the range.
        assert data[0].max() > 1.0 and data[0].min() < 0.2  # the scene's lighting, not precision
        assert data[-1].max() < data[0].max() and data[-1].min() > data[0].min()


@pytest.mark.slow  # starts a process or GL context
def test_unknown_environment_422(client):
    response = client.get(f"{API}/environments/beach/prefiltered")
    assert response.status_code == 422
    assert "environment" in response.text


@pytest.mark.server
def test_no_gl_driver_503(tmp_path):
    # The server's render processes inherit its environment: libglvnd then finds no EGL
    # vendor, as on a machine without a GL driver. (A server process of its own: render
    # processes fork from a fork server that keeps the environment it started with.)
    with (
        server_process(tmp_path / "data", __EGL_VENDOR_LIBRARY_FILENAMES=str(tmp_path / "no-vendor.json")) as server,
        loopback.Client(base_url=server.url, timeout=60) as other,
    ):
        response = other.get(f"{API}/environments/studio/prefiltered")
        assert response.status_code == 503
        assert response.json()["detail"].startswith("the preview renderer is unavailable: no GL context")
        assert other.get("/healthz").status_code == 200  # the rest of the service works
