"""
The service's rough / coated preview query, the LUT download
and the split-sum functions in the GLSL and HLSL pack downloads.
"""

from __future__ import annotations

import io
import subprocess

import moderngl
import numpy as np
import pytest

from fitting.shading.lut import decode_lut, default_lut, encode_lut, generate_lut
from fitting.shading.ibl import split_sum_model
from service.downloads import render_pack
from conftest import app_client
from test_snippets import materials

API = "/api/v1"


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    with app_client(tmp_path_factory.mktemp("ibl"), warm_pool=True, metrics_samples=30) as client:
        response = client.post(f"{API}/fits", json={"material": "Au"})
        assert response.status_code == 201, response.text
        yield client, response.json()


@pytest.mark.slow  # 2.7 s (all cases 2.7 s) in a --durations=0 run
def test_lut_download(shared):
    client, _ = shared
    response = client.get(f"{API}/ibl-lut")
    assert response.status_code == 200
    assert response.headers["content-type"] == "application/octet-stream"
    assert 'filename="cf_ibl_lut.cflut"' in response.headers["content-disposition"]
    assert response.content == encode_lut(default_lut())
    lut = decode_lut(response.content)
    assert lut.shape == (16, 64, 64)


@pytest.mark.gl
class TestRoughPreview:
    def test_rough_coated_png(self, shared):
        from PIL import Image

        client, fit = shared
        params = {
            "fit": fit["id"],
            "size": 64,
            "roughness": 0.4,
            "mode": "coated",
            "coat_roughness": 0.1,
            "environment": "studio",
            "compare": "lazanyi",
        }
        response = client.get(f"{API}/preview.png", params=params)
        assert response.status_code == 200, response.text
        rough = np.asarray(Image.open(io.BytesIO(response.content)).convert("RGB"))
        smooth = client.get(f"{API}/preview.png", params={"fit": fit["id"], "size": 64, "environment": "studio"})
        assert rough.shape == (64, 64, 3)
        assert not np.array_equal(rough, np.asarray(Image.open(io.BytesIO(smooth.content)).convert("RGB")))

    @pytest.mark.parametrize(
        ("params", "message"),
        [
            ({"roughness": 1.5}, "roughness"),
            ({"roughness": "nan"}, "roughness"),
            ({"coat_roughness": -0.5}, "coat_roughness"),
            ({"mode": "layered"}, "mode"),
        ],
    )
    def test_bad_query_422(self, shared, params, message):
        client, fit = shared
        response = client.get(f"{API}/preview.png", params={"fit": fit["id"], "size": 64, **params})
        assert response.status_code == 422
        assert message in response.json()["detail"]


FRAGMENT = """#version 430
%s
uniform sampler3D u_lut;
uniform vec2 u_alpha_range;
uniform vec3 u_F0, u_a, u_alpha;
uniform vec2 u_size;
out vec4 colour;
void main()
{
    vec2 uv = (gl_FragCoord.xy - 0.5) / (u_size - 1.0);
    colour = vec4(cf_split_sum_model(u_lut, u_alpha_range, uv.x, uv.y, u_F0, u_a, u_alpha), 1.0);
}
"""
VERTEX = """#version 430
void main() { vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0); }
"""


@pytest.mark.gl
def test_glsl_pack_split_sum_matches_numpy():
    source = render_pack(materials(), "glsl", "test pack").decode()
    assert "vec3 cf_split_sum_model(sampler3D lut" in source
    lut = generate_lut(shape=(4, 6, 8), samples=64)
    F0, a, alpha = np.array([0.6, 0.5, 0.4]), np.array([0.4, 0.3, 0.2]), np.array([5.0, 2.0, 0.9])
    ctx = moderngl.create_context(standalone=True, backend="egl")
    try:
        program = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT % source)
        size = (17, 9)
        n_alpha, n_r, n_mu = lut.shape
        texture = ctx.texture3d((n_mu, n_r, n_alpha), 3, lut.data.astype("f4").tobytes(), dtype="f4")
        texture.filter = (ctx.NEAREST, ctx.NEAREST)
        texture.use(0)
        program["u_lut"].value = 0
        program["u_alpha_range"].value = lut.alpha_range
        program["u_F0"].value, program["u_a"].value = tuple(F0), tuple(a)
        program["u_alpha"].value = tuple(alpha)
        program["u_size"].value = size
        target = ctx.texture(size, 4, dtype="f4")
        fbo = ctx.framebuffer(color_attachments=[target])
        fbo.use()
        ctx.vertex_array(program, []).render(mode=moderngl.TRIANGLES, vertices=3)
        got = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(size[1], size[0], 4)
        assert ctx.error == "GL_NO_ERROR"
    finally:
        ctx.release()
    mu = (np.arange(size[0]) / (size[0] - 1)).astype(np.float32)[None, :]
    r = (np.arange(size[1]) / (size[1] - 1)).astype(np.float32)[:, None]
    expected = split_sum_model(mu, r, F0, a, alpha, lut)
    # GLSL float32 against float64 numpy: GLSL_F32_BOUND (tests/precision.py).
    np.testing.assert_allclose(got[..., :3], expected, atol=1e-5)


HLSL_ENTRY = """
Texture3D<float4> cf_lut : register(t0);
float4 main(float4 position : SV_Position) : SV_Target
{
    float NdotV = saturate(position.x / 32.0);
    float3 F = cf_material_gold_1(NdotV, 1.5);
    float3 E = cf_split_sum_model(cf_lut, float2(0.5, 12.0), NdotV, 0.5, F, F, float3(2.0, 3.0, 4.0));
    E += cf_split_sum_lazanyi(cf_lut, float2(0.5, 12.0), NdotV, 0.5, F, F);
    E += cf_split_sum_schlick(cf_lut, float2(0.5, 12.0), NdotV, 0.5, F);
    E *= cf_average_fresnel(F, F, F);
    return float4(E, 1.0);
}
"""


@pytest.mark.slow  # starts a process or GL context
def test_hlsl_pack_split_sum_compiles(tmp_path):
    source = render_pack(materials(), "hlsl", "test pack").decode()
    assert "float3 cf_split_sum_model(Texture3D<float4> lut" in source
    path = tmp_path / "pack.hlsl"
    path.write_text(source + HLSL_ENTRY)
    result = subprocess.run(
        ["glslangValidator", "-D", "-V", "-S", "frag", "-e", "main", "-o", str(tmp_path / "p.spv"), str(path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert (tmp_path / "p.spv").stat().st_size > 0


@pytest.mark.slow  # starts a GL context
@pytest.mark.parametrize("head", ["#version 330\n", "#version 300 es\nprecision highp float;\n"])
def test_glsl_pack_split_sum_compiles_for_330_and_es_300(tmp_path, head):
    source = render_pack(materials(), "glsl", "test pack").decode()
    body = """
uniform highp sampler3D cf_lut;
out vec4 o;
void main()
{
    vec3 F = cf_material_gold_1(0.5, 1.5);
    vec3 E = cf_split_sum_model(cf_lut, vec2(0.5, 12.0), 0.5, 0.3, F, F, vec3(2.0, 3.0, 4.0))
        + cf_split_sum_lazanyi(cf_lut, vec2(0.5, 12.0), 0.5, 0.3, F, F)
        + cf_split_sum_schlick(cf_lut, vec2(0.5, 12.0), 0.5, 0.3, F);
    o = vec4(E * cf_average_fresnel(F, F, F), 1.0);
}
"""
    path = tmp_path / "pack.frag"
    path.write_text(head + source + body)
    result = subprocess.run(["glslangValidator", str(path)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, head + result.stdout
