"""The GLSL pack snippet compiles in a real GL context and evaluates the model exactly as numpy."""

from __future__ import annotations

import subprocess

import moderngl
import numpy as np
import pytest

from fitting.models.coated_conductor import coated_conductor_model
from fitting.models.pack import PackedMaterial, material_to_json
from service.downloads import glsl_identifier, render_pack
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


def record(name: str, coefficients: np.ndarray, eta_i_range=(1.0, 2.5), fit_id="a" * 32) -> FitRecord:
    packed = PackedMaterial(name, np.asarray(coefficients, dtype=np.float16), eta_i_range, "test")
    return FitRecord(
        id=fit_id,
        kind="curves",
        material_id=fit_id,
        name=name,
        source="a\nb // c \\",
        material=material_to_json(packed),
    )


def materials() -> list[FitRecord]:
    rng = np.random.default_rng(7)
    quadratic = np.stack([rng.uniform(0.1, 0.9, (3, 3)), rng.uniform(-0.5, 0.5, (3, 3)), rng.uniform(1.0, 8.0, (3, 3))])
    constant = quadratic[:, :, :1]
    return [
        record("gold 1", quadratic),
        record("gold 1", quadratic * 0.9, (1.2, 1.8), "b" * 32),  # same name: unique identifier
        record("9 lives", constant, (1.5, 1.5), "c" * 32),  # degree 0, single eta_i
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
def test_glsl_snippet_matches_numpy(index):
    records = materials()
    source = render_pack(records, "glsl", "test pack").decode()
    identifiers = ["gold_1", "gold_1_2", "m_9_lives"]
    for ident in identifiers:
        assert f"vec3 cf_material_{ident}(float NdotV, float eta_i)" in source
    image = render(source, f"cf_material_{identifiers[index]}")
    view = records[index].material
    coefficients = np.array([view["coefficients"][p] for p in ("F0", "a", "alpha")])
    mu = np.linspace(0.0, 1.0, image.shape[1])[None, :]
    eta = np.linspace(1.0, 3.0, image.shape[0])[:, None]
    expected = coated_conductor_model(mu, eta, coefficients, tuple(view["eta_i_range"]))
    # The snippet in float32 GLSL against float64 numpy: GLSL_F32_BOUND
    # (tests/precision.py) plus the float32 grid coordinates (u32 x the
    # model's slope <= ~10 = 6e-7) and the JSON coefficients' float32
    # literals in the source (u32 x terms <= ~6 = 4e-7): 2e-5 with room.
    np.testing.assert_allclose(image, expected, atol=2e-5)


HLSL_ENTRY = """
float4 main(float4 position : SV_Position) : SV_Target
{
    float NdotV = saturate(position.x / 32.0);
    float eta_i = 1.0 + position.y / 8.0;
    return float4(%s, 1.0);
}
"""


@pytest.mark.slow  # starts a process or GL context
def test_hlsl_snippet_compiles(tmp_path):
    # glslang's HLSL front end (Debian glslang-tools) compiles the snippet to
    # SPIR-V as a pixel shader calling every material function.
    source = render_pack(materials(), "hlsl", "test pack").decode()
    calls = " + ".join(f"cf_material_{i}(NdotV, eta_i)" for i in ("gold_1", "gold_1_2", "m_9_lives"))
    path = tmp_path / "pack.hlsl"
    path.write_text(source + HLSL_ENTRY % calls)
    result = subprocess.run(
        ["glslangValidator", "-D", "-V", "-S", "frag", "-e", "main", "-o", str(tmp_path / "pack.spv"), str(path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert (tmp_path / "pack.spv").stat().st_size > 0
    broken = tmp_path / "broken.hlsl"
    broken.write_text(source + HLSL_ENTRY % "cf_material_missing(NdotV, eta_i)")
    result = subprocess.run(
        ["glslangValidator", "-D", "-V", "-S", "frag", "-e", "main", str(broken)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode != 0


def test_snippet_comments_cannot_break_out():
    source = render_pack(materials(), "glsl", "x\ny").decode()
    for line in source.splitlines():
        assert not line.rstrip().endswith("\\")
    cited = [line for line in source.splitlines() if "a b // c" in line]
    assert len(cited) == 3 and all(line.startswith("// ") for line in cited)


@pytest.mark.parametrize(
    ("name", "ident"),
    [("Au", "Au"), ("my gold", "my_gold"), ("a__b", "a_b"), ("9", "m_9"), ("", "m"), ("ÿ€", "m")],
)
def test_identifier(name, ident):
    assert glsl_identifier(name) == ident
