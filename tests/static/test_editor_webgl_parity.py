"""
The editor's WebGL2 preview against numpy, in a real Chromium (SwiftShader
WebGL2): the project's GLSL (preview_shaders/glsl/shader_ball.frag and its
includes, loaded as GLSL ES 3.00) rendered into an RGBA32F target
(EXT_color_buffer_float) and read back; at every pixel of a 96 x 64 view the
camera geometry, the model from its packed float16 halves, adjusted
Lazanyi, the spectral reference from the service's texture and the display
transform agree with numpy (fitting.models, fitting.fits.curves_base,
preview_shaders.display).
"""

from __future__ import annotations

import numpy as np
import pytest
from editor_pages import camera_rays, editor_url, open_editor, pages, read_float, chromium, live_server  # noqa: F401 (fixtures: one server and one Chromium a module)

from fitting import (
    baseline_inputs,
    coated_conductor_model,
    curve_base_from_nk,
    halves_to_uint32,
    lazanyi_adjusted,
    library_material,
)
from preview_shaders.display import ACEScg_to_sRGB

pytestmark = [pytest.mark.server, pytest.mark.browser]

W, H = 96, 64

# The documented parity figures (docs/editor.md, "Parity"): SwiftShader's
# float32 GLSL ES 3.00 against numpy at the same float32 inputs. The model,
# Lazanyi and the reference: 2e-5, twice tests/precision.py's
# GLSL_F32_BOUND (1e-5: the model's roundings and pow's exp2/log2 error)
# for the camera's float32 cos theta (~3 u32 / z at the view's pixels) and
# the reference texture's bilinear fetch. The camera cos theta itself:
# 2e-5 (the ray-sphere intersection's sqrt, condition 1 / z near the rim).
PARITY_BOUND = 2e-5
# The display transform (ACEScg -> sRGB, a pow(1 / 2.4)): the encoding's
# slope, up to ~12.9 near black, times the linear value's error and pow's
# error: 2e-4 (docs/editor.md).
DISPLAY_BOUND = 2e-4


def read(page, output: str):
    """(H, W, 4) floats of OUTPUT.<output>, top row first."""
    return read_float(page, output, W, H)


def test_preview_matches_numpy(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    page.select_option("#environment", "white_sky")
    page.select_option("#compare", "all")
    fit_id = page.inner_text("#fit-id")
    fit = page.evaluate(f"fetch('/api/v1/fits/{fit_id}').then(r => r.json())")
    state = page.evaluate(
        "(() => { const s = window.cfPreview.state;"
        " return {orbit: s.orbit, fov: s.fov, eta: s.eta, words: Array.from(s.words),"
        " panels: s.panels}; })()"
    )
    assert state["panels"] == [0, 1, 2]
    C = np.array([fit["coefficients"][p] for p in ("F0", "a", "alpha")])
    assert C.shape == (3, 3, 3)
    # The page's float16 halves are numpy's, bit for bit.
    assert state["words"] == halves_to_uint32(C.astype(np.float16)).tolist()

    geometry, fresnel, linear, display = (read(page, o) for o in ("geometry", "fresnel", "linear", "display"))
    NdotV, hit, band, _ = camera_rays(*state["orbit"], state["fov"], W, H)
    gl_hit = geometry[..., 1] > 0.5
    # Pixels whose centre is this close to the silhouette may round either way.
    assert np.mean(gl_hit != hit) < 0.01  # silhouette pixels, a count, not precision
    both = gl_hit & hit
    assert both.sum() > 0.25 * W * H
    np.testing.assert_allclose(geometry[..., 0][both], NdotV[both], atol=PARITY_BOUND)
    np.testing.assert_array_equal(geometry[..., 2][both], band[both])

    # Fresnel at the GL's own cos theta, per band.
    mu = geometry[..., 0]
    eta = state["eta"]
    nk = library_material("Au")
    inputs = baseline_inputs(nk)
    expected = np.zeros((H, W, 3))
    model = coated_conductor_model(mu, eta, C, tuple(fit["eta_i_range"]))
    lazanyi = lazanyi_adjusted(mu, eta, inputs["F0_air"], inputs["F82_air"])
    reference = curve_base_from_nk(nk, tuple(fit["eta_i_range"])).rgb(mu, eta)
    for k, values in enumerate((model, lazanyi, reference)):
        mask = gl_hit & (geometry[..., 2] == k)
        assert mask.sum() > 100
        expected[mask] = values[mask]
        np.testing.assert_allclose(
            fresnel[..., :3][mask],
            values[mask],
            atol=PARITY_BOUND,
            rtol=PARITY_BOUND,
            err_msg=["model", "adjusted Lazanyi", "spectral reference"][k],
        )
    # The bands differ (the reference is not the model, Lazanyi is neither).
    assert np.abs(model - reference)[gl_hit].max() > 1e-3
    assert np.abs(model - lazanyi)[gl_hit].max() > 1e-3

    # White sky of radiance 1, exposure 0: the radiance is F; the canvas shows it sRGB-encoded.
    # Radiance 1, exposure 0: one float32 product by 1.0 (exact) and the
    # white sky's texel: equal up to a rounding, 1e-6 = 17 u32.
    np.testing.assert_allclose(linear[..., :3][gl_hit], fresnel[..., :3][gl_hit], atol=1e-6)
    np.testing.assert_allclose(linear[..., :3][~gl_hit], 1.0, atol=1e-6)
    np.testing.assert_allclose(display[..., :3][gl_hit], ACEScg_to_sRGB(expected[gl_hit]), atol=DISPLAY_BOUND)

    # Exposure scales the radiance by 2^stops.
    page.fill("#exposure", "1.5")
    page.dispatch_event("#exposure", "input")
    brighter = read(page, "linear")
    np.testing.assert_allclose(brighter[..., :3][gl_hit], 2**1.5 * linear[..., :3][gl_hit], rtol=1e-5)  # 2^1.5 via
    # exp2 (3 ulps) and one product: 4 u32 = 2.4e-7, inside 1e-5


def test_environments_and_orbit_change_the_view(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    views = {}
    for environment in ("white_sky", "studio", "outdoor"):
        page.select_option("#environment", environment)
        views[environment] = read(page, "linear")
    # The studio and the outdoor scene are lit unevenly, the outdoor one brighter.
    for environment in ("studio", "outdoor"):
        assert views[environment][..., :3].std() > 0.05
    assert views["outdoor"][..., :3].mean() > views["studio"][..., :3].mean()
    np.testing.assert_allclose(views["white_sky"][..., :3][read(page, "geometry")[..., 1] < 0.5], 1.0)  # the sky is
    # exactly 1 (default rtol=1e-7 admits one float32 rounding of 1: u32 = 6e-8)

    # Orbit (drag on the canvas) and zoom (wheel) move the camera.
    before = page.evaluate("window.cfPreview.state.orbit.slice()")
    box = page.locator("#preview").bounding_box()
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(cx, cy)
    page.mouse.down()
    page.mouse.move(cx + 60, cy + 20, steps=4)
    page.mouse.up()
    page.mouse.wheel(0, 300)
    after = page.evaluate("window.cfPreview.state.orbit.slice()")
    # The orbit state in JavaScript doubles: a few roundings (1e-15); 1e-6
    # is loose and harmless (these are event-handling checks).
    assert after[0] == pytest.approx(before[0] - 0.6, abs=1e-6)
    assert after[1] == pytest.approx(before[1] + 0.2, abs=1e-6)
    assert after[2] == pytest.approx(before[2] * np.exp(0.3), rel=1e-6)
    assert not np.allclose(read(page, "linear"), views["outdoor"])
    # The three bands are labelled.
    assert page.inner_text("#preview-labels").split("\n") == ["Model", "Adjusted Lazanyi", "Spectral reference"]
