"""
The rgb-conductor model kind through the HTTP service: ``"model"`` in
``POST /api/v1/fits`` (default coated-conductor, 422 for an unknown kind),
the stored fit's view, and its downloads (binary, json, glsl, hlsl).
"""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from conftest import app_client
from fitting.models.rgb_conductor import rgb_conductor_model
from fitting.models.pack import PACK_VERSION, decode_pack, pack_from_json

API = "/api/v1"


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """One app with Au fitted as an rgb-conductor and as the default kind."""
    with app_client(tmp_path_factory.mktemp("rgbkind"), metrics_samples=30) as client:
        rgb = client.post(f"{API}/fits?metrics=full", json={"material": "Au", "model": "rgb-conductor"})
        assert rgb.status_code == 201, rgb.text
        coated = client.post(f"{API}/fits?metrics=full", json={"material": "Au"})
        assert coated.status_code == 201, coated.text
        yield client, rgb.json(), coated.json()


@pytest.mark.slow  # its shared fixture's fits start the fitting pool's processes
class TestCreateFit:
    @pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
    def test_rgb_conductor_view(self, fitted):
        _, rgb, _ = fitted
        assert rgb["model"] == "rgb-conductor"
        assert set(rgb["coefficients"]) == {"n", "k"}
        n, k = np.array(rgb["coefficients"]["n"]), np.array(rgb["coefficients"]["k"])
        assert n.shape == k.shape == (3,)
        # Exactly the stored float16 values.
        assert np.array_equal(n.astype(np.float16).astype(np.float64), n)
        assert np.array_equal(k.astype(np.float16).astype(np.float64), k)
        assert rgb["metrics"]["model"]["delta_E_mean"] < rgb["metrics"]["lazanyi_adjusted"]["delta_E_mean"]

    @pytest.mark.slow  # starts a process or GL context
    def test_default_kind_unchanged(self, fitted):
        _, rgb, coated = fitted
        assert coated["model"] == "coated-conductor"
        assert set(coated["coefficients"]) == {"F0", "a", "alpha"}
        assert coated["id"] != rgb["id"]

    @pytest.mark.slow  # starts a process or GL context
    def test_same_request_served_from_store(self, fitted):
        client, rgb, _ = fitted
        again = client.post(f"{API}/fits", json={"material": "Au", "model": "rgb-conductor"})
        assert again.status_code == 200
        assert again.json()["id"] == rgb["id"]
        got = client.get(f"{API}/fits/{rgb['id']}")
        assert got.status_code == 200 and got.json()["coefficients"] == rgb["coefficients"]

    def test_unknown_model_is_422(self, fitted):
        client, _, _ = fitted
        response = client.post(f"{API}/fits", json={"material": "Au", "model": "cook-torrance"})
        assert response.status_code == 422
        assert "rgb-conductor" in response.text and "model" in response.text

    def test_curves_of_the_kind(self, fitted):
        client, rgb, _ = fitted
        response = client.get(f"{API}/fits/{rgb['id']}/curves", params={"eta_i": 1.5, "samples": 10})
        assert response.status_code == 200
        body = response.json()
        C = np.array([rgb["coefficients"]["n"], rgb["coefficients"]["k"]])
        expected = rgb_conductor_model(np.array(body["cos_theta"]), 1.5, C)
        np.testing.assert_allclose(body["model"], expected, atol=1e-12)  # the same
        # float64 kernel on JSON-exact inputs: a few u64


class TestDownloads:
    def test_binary_is_version_2_rgb_conductor(self, fitted):
        client, rgb, _ = fitted
        response = client.get(f"{API}/fits/{rgb['id']}/pack", params={"format": "binary"})
        assert response.status_code == 200
        assert int.from_bytes(response.content[4:6], "little") == PACK_VERSION == 2
        (material,) = decode_pack(response.content)
        assert material.model == "rgb-conductor"
        assert material.coefficients.astype(np.float64).tolist() == [rgb["coefficients"]["n"], rgb["coefficients"]["k"]]

    def test_json(self, fitted):
        client, rgb, _ = fitted
        response = client.get(f"{API}/fits/{rgb['id']}/pack", params={"format": "json"})
        assert response.status_code == 200
        view = json.loads(response.content)["materials"][0]
        assert view["model"] == "rgb-conductor"
        assert view["coefficients"] == rgb["coefficients"]
        assert pack_from_json(response.content)[0].model == "rgb-conductor"

    @pytest.mark.slow  # starts a process or GL context
    def test_glsl_and_hlsl(self, fitted, tmp_path):
        client, rgb, _ = fitted
        glsl = client.get(f"{API}/fits/{rgb['id']}/pack", params={"format": "glsl"})
        assert glsl.status_code == 200
        assert "vec3 cf_material_Au(float NdotV, float eta_i)" in glsl.text
        assert "cf_rgb_conductor(" in glsl.text and "cf_coated_conductor(" not in glsl.text
        hlsl = client.get(f"{API}/fits/{rgb['id']}/pack", params={"format": "hlsl"})
        assert hlsl.status_code == 200
        entry = "\nfloat4 main(float4 p : SV_Position) : SV_Target\n{\n    return float4(%s, 1.0);\n}\n"
        path = tmp_path / "pack.hlsl"
        path.write_text(hlsl.text + entry % "cf_material_Au(saturate(p.x / 32.0), 1.5)")
        result = subprocess.run(
            ["glslangValidator", "-D", "-V", "-S", "frag", "-e", "main", "-o", str(tmp_path / "p.spv"), str(path)],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert result.returncode == 0, result.stdout + result.stderr

    def test_exports_of_an_rgb_conductor_fit(self, fitted):
        client, rgb, _ = fitted
        response = client.get(f"{API}/fits/{rgb['id']}/pack", params={"format": "mtlx", "eta_i": 1.5})
        assert response.status_code == 200
        assert b"conductor_bsdf" in response.content

    def test_bad_format_is_422(self, fitted):
        client, rgb, _ = fitted
        response = client.get(f"{API}/fits/{rgb['id']}/pack", params={"format": "usd"})
        assert response.status_code == 422
