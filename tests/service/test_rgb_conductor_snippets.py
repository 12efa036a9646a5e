"""
A GLSL / HLSL download holding both model kinds: each kind's function once,
the GLSL compiled in a real EGL context and evaluated against numpy, the HLSL
compiled by glslang's HLSL front end.
"""

from __future__ import annotations

import subprocess

import moderngl
import numpy as np
import pytest

from fitting.models.kinds import model_ACEScg
from fitting.models.pack import PackedMaterial, material_from_json, material_to_json, to_float16
from service.downloads import render_pack
from service.store import FitRecord

VERTEX = """#version 420 core
void main()
{
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
"""

# Column i: NdotV = i / (W - 1); row j: eta_i = 1 + 2 j / (H - 1).
FRAGMENT = """#version 420 core
uniform vec2 u_size;
out vec4 colour;
%s
void main()
{
    vec2 cell = floor(gl_FragCoord.xy);
    float NdotV = cell.x / (u_size.x - 1.0);
    float eta_i = 1.0 + 2.0 * cell.y / (u_size.y - 1.0);
    colour = vec4(%s(NdotV, eta_i), 1.0);
}
"""


def _record(name, packed, fit_id):
    return FitRecord(
        id=fit_id, kind="library", material_id=name, name=name, source="test", material=material_to_json(packed)
    )


def mixed() -> list[FitRecord]:
    rng = np.random.default_rng(3)
    coated = np.stack([rng.uniform(0.1, 0.9, (3, 3)), rng.uniform(-0.5, 0.5, (3, 3)), rng.uniform(1.0, 8.0, (3, 3))])
    return [
        _record(
            "gold",
            PackedMaterial(
                "gold", to_float16([[0.26, 0.4727, 1.317], [3.029, 2.3125, 1.923]]), (1.0, 2.5), model="rgb-conductor"
            ),
            "a" * 32,
        ),
        _record("paper", PackedMaterial("paper", to_float16(coated), (1.0, 2.5)), "b" * 32),
        _record(
            "glassy",
            PackedMaterial("glassy", to_float16([[1.2, 1.6, 2.8], [0.3, 0.1, 0.0]]), (1.0, 2.5), model="rgb-conductor"),
            "c" * 32,
        ),
    ]


def render(source: str, function: str, size=(33, 9)) -> np.ndarray:
    ctx = moderngl.create_context(standalone=True, backend="egl")
    try:
        program = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT % (source, function))
        program["u_size"].value = size
        target = ctx.texture(size, 4, dtype="f4")
        fbo = ctx.framebuffer(color_attachments=[target])
        fbo.use()
        ctx.vertex_array(program, []).render(mode=moderngl.TRIANGLES, vertices=3)
        pixels = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(size[1], size[0], 4)
        assert ctx.error == "GL_NO_ERROR"
        return pixels[..., :3].astype(np.float64)
    finally:
        ctx.release()


@pytest.mark.gl
@pytest.mark.parametrize("index", [0, 1, 2])
def test_mixed_glsl_snippet_matches_numpy(index):
    records = mixed()
    source = render_pack(records, "glsl", "mixed").decode()
    assert source.count("vec3 cf_fresnel_conductor(") == 1
    assert source.count("vec3 cf_coated_conductor(") == 1
    image = render(source, f"cf_material_{records[index].name}")
    packed = material_from_json(records[index].material)
    mu = np.linspace(0.0, 1.0, image.shape[1])[None, :]
    eta = np.linspace(1.0, 3.0, image.shape[0])[:, None]
    expected = model_ACEScg(packed.model, mu, eta, packed.coefficients.astype(np.float64), packed.eta_i_range)
    # The k = 0 channel of "glassy" has a critical angle; float32 rounding of
    # 1 - sin^2 dominates right at it, so compare away from it.
    error = np.abs(image - expected)
    if records[index].name == "glassy":
        sin2 = (eta / float(packed.coefficients[0, 2])) ** 2 * (1.0 - mu**2)
        error[..., 2] = np.where(np.abs(1.0 - sin2) > 1e-2, error[..., 2], 0.0)
    # The exact Fresnel snippet in float32 GLSL (away from the critical
    # angle's cancelling 1 - sin^2, masked above): 2 x GLSL_F32_BOUND
    # (tests/precision.py) for the complex square root's extra roundings.
    assert error.max() <= 2e-5


@pytest.mark.slow  # starts a process or GL context
def test_mixed_hlsl_snippet_compiles(tmp_path):
    source = render_pack(mixed(), "hlsl", "mixed").decode()
    assert source.count("float3 cf_rgb_conductor(") == 1 and source.count("float3 cf_coated_conductor(") == 1
    entry = (
        "\nfloat4 main(float4 p : SV_Position) : SV_Target\n{\n    float m = saturate(p.x / 32.0);\n"
        "    return float4(cf_material_gold(m, 1.5) + cf_material_paper(m, 1.5) + cf_material_glassy(m, 2.0), 1.0);\n}\n"
    )
    path = tmp_path / "mixed.hlsl"
    path.write_text(source + entry)
    result = subprocess.run(
        ["glslangValidator", "-D", "-V", "-S", "frag", "-e", "main", "-o", str(tmp_path / "m.spv"), str(path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stdout + result.stderr
