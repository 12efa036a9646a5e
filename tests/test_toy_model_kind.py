"""
A third model kind is one registration per layer.

A toy kind, Schlick's approximation with a constant F0 per channel (3
float16), registered here and nowhere else (its numpy model, its fit, its
GLSL file and snippet template written by the test), flows through the fit
pipeline, the binary and JSON packs, the GLSL snippet of a download and the
headless preview, with no other module changed.
"""

from __future__ import annotations

import time

import moderngl
import numpy as np
import pytest
from scipy.optimize import least_squares

from fitting.fits.kinds import fit_model, register_fit_kind, unregister_fit_kind
from fitting.fits.pipeline import FitKind
from fitting.fits.result import FitResult
from fitting.fits.settings import FitSettings
from fitting.models.kinds import MODEL_KINDS, ModelKind, register_model_kind, unregister_model_kind
from fitting.models.pack import decode_pack, encode_pack, material_to_json, pack_from_json, pack_to_json, to_float16
from fitting.optics.library import library_material
from preview_shaders.preview import PreviewRenderer
from fitting.exports.snippets import SnippetMaterial, snippet
from fitting.fits.metrics import headline

TOY = "toy-schlick"

TOY_GLSL = """// The toy kind of tests/test_toy_model_kind.py: Schlick with a constant F0.
#ifndef CF_TOY_SCHLICK_GLSL
#define CF_TOY_SCHLICK_GLSL
vec3 cf_toy_schlick(float NdotV, float eta_i, vec3 F0)
{
    float m = clamp(1.0 - NdotV, 0.0, 1.0);
    float m2 = m * m;
    return F0 + (1.0 - F0) * (m2 * m2 * m);
}
vec3 cf_toy_schlick_packed(float NdotV, float eta_i, uint words[14])
{
    vec2 rg = unpackHalf2x16(words[0]);
    return cf_toy_schlick(NdotV, eta_i, vec3(rg, unpackHalf2x16(words[1]).x));
}
#endif
"""

TOY_TEMPLATE = """
// ${name}: ${source}
// Fit ${fit_id} (${model}); ${quality}.
const vec3 ${prefix}_F0 = vec3(${F0});

vec3 cf_material_${ident}(float NdotV, float eta_i)
{
    return cf_toy_schlick(NdotV, eta_i, ${prefix}_F0);
}
"""


def check_toy(coefficients) -> np.ndarray:
    C = np.asarray(coefficients, dtype=np.float64)
    if C.shape != (1, 3) or not np.all(np.isfinite(C)) or not np.all((C >= 0) & (C <= 1)):
        raise ValueError(f"`coefficients` of a {TOY} must be (1, 3) in [0, 1], got {C.tolist()}")
    return C


def toy_model(cos_theta, eta_i, coefficients, eta_i_range) -> np.ndarray:
    F0 = np.asarray(coefficients, dtype=np.float64)[0]
    mu = np.clip(np.broadcast_arrays(np.asarray(cos_theta, dtype=np.float64), np.asarray(eta_i))[0], 0.0, 1.0)
    return F0 + (1.0 - F0) * (1.0 - mu[..., None]) ** 5


def toy_solve(
    target, mu, eta, eta_i_range, degree, objective, max_nfev, quantise, weights=None, irls_rounds=2
) -> FitResult:
    """Least squares of F0 in linear RGB (the toy ignores the objective and the coating)."""
    t0 = time.perf_counter()
    w = np.ones(len(mu)) if weights is None else np.asarray(weights)
    solution = least_squares(
        lambda x: ((toy_model(mu, eta, x[None, :], eta_i_range) - target) * np.sqrt(w)[:, None]).ravel(),
        np.full(3, 0.5),
        bounds=(0.0, 1.0),
        max_nfev=max_nfev,
    )
    C = solution.x[None, :]
    C16 = to_float16(C)
    residual = (toy_model(mu, eta, C16.astype(np.float64), eta_i_range) - target) * np.sqrt(w)[:, None]
    return FitResult.from_solve(
        solution,
        C,
        C16,
        eta_i_range,
        0,
        objective,
        solution.nfev,
        solution.njev or 0,
        0.5 * float(np.sum(residual**2)),
        {"fit": time.perf_counter() - t0, "quantise": 0.0},
        model=TOY,
    )


@pytest.fixture(scope="module")
def toy(tmp_path_factory):
    folder = tmp_path_factory.mktemp("toy_kind")
    (folder / "cf_toy_schlick.glsl").write_text(TOY_GLSL)
    (folder / "material_toy.glsl").write_text(TOY_TEMPLATE)
    kind = register_model_kind(
        ModelKind(
            name=TOY,
            code=200,
            description="toy: Schlick with a constant F0",
            parameters=("F0",),
            max_degree=0,
            check=check_toy,
            evaluate=toy_model,
            glsl_file=str(folder / "cf_toy_schlick.glsl"),
            hlsl_file=str(folder / "none.hlsl"),
            glsl_function="cf_toy_schlick",
            preview_call="cf_toy_schlick_packed(NdotV, eta_i, words)",
            material_template=str(folder / "material_toy"),
        )
    )
    register_fit_kind(FitKind(name=TOY, settings=FitSettings(), solve=toy_solve, bounded=True))
    try:
        yield kind
    finally:
        unregister_fit_kind(TOY)
        unregister_model_kind(TOY)
    assert TOY not in MODEL_KINDS


@pytest.fixture(scope="module")
def fitted(toy):
    return fit_model(library_material("Au"), model=TOY, evaluate=True, samples=None)


def test_the_fit_pipeline_fits_the_toy(fitted):
    assert fitted.model == fitted.packed.model == TOY
    assert fitted.packed.coefficients.shape == (1, 3) and fitted.packed.degree == 0
    assert fitted.settings == FitSettings()
    figure = fitted.metrics["figure"]
    assert figure["against"].startswith("the measured metal (1 nm spectral reference)")
    # Gold's F0 in ACEScg is far from grey: the toy follows it to within a few Delta E.
    assert figure["delta_E_mean"] < 10.0 and figure["delta_E_max"] >= figure["delta_E_mean"]
    assert set(fitted.timings) >= {"reference", "fit", "quantise", "evaluate", "total"}


def test_the_packs_carry_the_toy(fitted, toy):
    (back,) = decode_pack(encode_pack([fitted.packed]))
    assert back == fitted.packed and back.model == TOY
    (again,) = pack_from_json(pack_to_json([fitted.packed]))
    assert again == fitted.packed
    assert material_to_json(fitted.packed)["coefficients"] == {"F0": [float(v) for v in fitted.packed.coefficients[0]]}


def toy_record(fitted) -> SnippetMaterial:
    return SnippetMaterial(
        name="toy gold", source="test", fit_id="d" * 32, quality=headline(fitted.metrics), packed=fitted.packed
    )


def test_the_glsl_snippet_has_the_toy(fitted):
    source = snippet("glsl", [toy_record(fitted)], "toy pack", "test")
    assert "vec3 cf_toy_schlick(float NdotV" in source
    assert "cf_toy_schlick_packed" not in source  # only what the material blocks call
    assert "vec3 cf_material_toy_gold(float NdotV, float eta_i)" in source
    assert "cf_split_sum_model" not in source  # the toy has no split-sum lookup
    figure = fitted.metrics["figure"]
    assert f"mean {figure['delta_E_mean']:.3f}" in source


VERTEX = """#version 430
void main()
{
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
"""
FRAGMENT = """#version 430
out vec4 colour;
%s
void main()
{
    float NdotV = floor(gl_FragCoord.x) / 32.0;
    colour = vec4(cf_material_toy_gold(NdotV, 1.5), 1.0);
}
"""


@pytest.mark.gl
def test_the_glsl_snippet_compiles_and_matches_numpy(fitted):
    source = snippet("glsl", [toy_record(fitted)], "toy pack", "test")
    ctx = moderngl.create_context(standalone=True, backend="egl")
    try:
        program = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT % source)
        target = ctx.texture((33, 1), 4, dtype="f4")
        fbo = ctx.framebuffer(color_attachments=[target])
        fbo.use()
        ctx.vertex_array(program, []).render(mode=moderngl.TRIANGLES, vertices=3)
        image = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(33, 4)[:, :3]
    finally:
        ctx.release()
    mu = np.arange(33) / 32.0
    expected = toy_model(mu, 1.5, fitted.packed.coefficients.astype(np.float64), None)
    # Float32 Schlick against float64: (1 - mu)^5 by 4 products and 3 more
    # roundings of values <= 1: 8 u32 = 4.8e-7; 1e-6 with room.
    np.testing.assert_allclose(image, expected, atol=1e-6)


@pytest.mark.gl
def test_the_headless_preview_draws_the_toy(fitted):
    with PreviewRenderer() as renderer:
        view = renderer.render_preview(fitted.packed, size=64)
    mask = view.mask
    expected = (
        toy_model(view.cos_theta[mask].astype(np.float64), 1.5, fitted.packed.coefficients.astype(np.float64), None)
        * view.radiance[mask]
    )
    # The same float32 Schlick as above at the preview's own cos theta, times
    # the white sky's radiance (1): 1e-6.
    assert np.abs(view.model[mask] - expected).max() < 1e-6
    assert view.png[:8] == b"\x89PNG\r\n\x1a\n"
