"""
An rgb-conductor fit opens in the editor: a curve fit of the
rgb-conductor kind (POST /api/v1/fits/from-curves with ``"model":
"rgb-conductor"``), saved and picked in the material list, opens in a real
Chromium (SwiftShader WebGL2) against a real server with no console error;
the plot draws its curves, the readout its n and k, and the preview draws
it: every pixel of a 96 x 64 float read-back of its model band agrees with
numpy (fitting.models.rgb_conductor) at the GL's own cosine, smooth and
rough (the split sum's table from model_albedo_table.frag, the kind's own Fresnel); an edit refits it
as an rgb-conductor (a live refit, then the full one).

Tolerances (float32 GLSL ES 3.00 against float64 numpy at the same float32
inputs):

-   ``FRESNEL`` 2e-5: the exact conductor Fresnel (cf_fresnel_conductor) is
    ~40 roundings (+, -, *, /, sqrt, each within 2.5 ulps) of terms up to
    |eta|^2 <= (k / eta_i)^2 ~ 10 for copper, a relative error of ~100 u32
    = 6e-6 on its terms, R in [0, 1]: 1e-5 absolute (tests/precision.py's
    GLSL_F32_BOUND), doubled for the one cancelling difference, 1 - sin^2
    theta_t, of size >= 1 - 1 / |eta|^2 > 0.9 here. Measured 1.6e-7.
-   ``TABLE`` 3e-4: its GGX table (2048 Hammersley points a node, the
    quadrature of the reference's table) against
    fitting.shading.ibl.directional_albedo: SwiftShader's sin and cos err by
    up to 1.9e-4, as for the reference band's table
    (tests/static/test_editor_webgl_rough.py, docs/editor.md). Measured
    1.1e-4 (Cu, roughness 0.45).
-   ``EXACT`` 2e-6: a pixel's albedo against its read-back table
    interpolated at its read-back cosine (only float32 rounding); measured
    3.5e-8.
-   ``DISPLAY`` 2e-4: the sRGB-encoded canvas (the encoding's slope up to
    12.9 near black times the linear error, and pow's), as the
    coated-conductor parity (test_editor_webgl_parity.py).
"""

from __future__ import annotations

import loopback
import numpy as np
import pytest
from editor_pages import camera_rays, open_editor, pages, read_float, chromium, live_server  # noqa: F401 (fixtures: one server and one Chromium a module)
from playwright.sync_api import expect

from fitting import curve_base_from_nk, library_material
from fitting.models.rgb_conductor import rgb_fresnel_conductor
from fitting.shading.ibl import directional_albedo
from preview_shaders.display import ACEScg_to_sRGB

pytestmark = [pytest.mark.server, pytest.mark.browser]

W, H = 96, 64
NODES = 127
MU = (np.arange(NODES) / (NODES - 1)) ** 2
FRESNEL = 2.0e-5
TABLE = 3.0e-4
EXACT = 2.0e-6
DISPLAY = 2.0e-4
ANGLES = np.linspace(0.0, 90.0, 19)


@pytest.fixture(scope="module")
def rgb_fit(live_server):
    """A saved rgb-conductor curve fit of copper with its blue raised (as tests/service/test_curves_kinds_api.py)."""
    mu = np.where(ANGLES == 90.0, 0.0, np.cos(np.radians(ANGLES)))
    rgb = curve_base_from_nk(library_material("Cu")).rgb(mu, 1.5)
    rgb[:, 2] *= 1.1
    body = {
        "name": "cool copper",
        "base": {"material": "Cu"},
        "model": "rgb-conductor",
        "curves": [{"eta_i": 1.5, "angle_deg": ANGLES.tolist(), "rgb": np.clip(rgb, 0, 1).tolist()}],
    }
    response = loopback.post(f"{live_server}/api/v1/fits/from-curves", json=body, timeout=300)
    assert response.status_code == 201, response.text
    fit = response.json()
    assert fit["model"] == "rgb-conductor" and set(fit["coefficients"]) == {"n", "k"}
    return fit


def open_rgb(page, live_server, fit):
    open_editor(page, live_server + "/")
    value = f"saved:{fit['material_id']}"
    assert page.locator(f"#material option[value='{value}']").count() == 1
    page.select_option("#material", value)
    expect(page.locator("#fit-id")).to_have_text(fit["id"])
    page.wait_for_function(
        "!document.body.hasAttribute('aria-busy')"
        " && document.getElementById('preview').dataset.fit === document.getElementById('fit-id').textContent"
    )


def nk(fit):
    return (np.asarray(fit["coefficients"][p], dtype=np.float64) for p in ("n", "k"))


def test_rgb_conductor_opens_and_its_preview_is_numpy(pages, live_server, rgb_fit):
    page = pages.new()
    open_rgb(page, live_server, rgb_fit)
    # The page shows it as an rgb-conductor: readout, plot, preview.
    assert page.text_content("#coefficients").startswith("rgb-conductor")  # in a closed <details>
    assert page.get_attribute("#preview", "data-model") == "rgb-conductor"
    assert page.get_attribute("#preview", "data-program") == "mirror"
    assert page.locator("#plot svg .model path").count() == 3
    assert page.inner_text("#de-mean") not in ("", "–")

    page.select_option("#environment", "white_sky")
    page.select_option("#compare", "none")  # the whole ball is the model band
    state = page.evaluate(
        "(() => { const s = window.cfPreview.state;"
        " return {orbit: s.orbit, fov: s.fov, eta: s.eta, words: Array.from(s.words), panels: s.panels}; })()"
    )
    assert state["panels"] == [0]
    n, k = nk(rgb_fit)
    halves = np.concatenate([n, k]).astype(np.float16).view(np.uint16).astype(np.uint32)
    assert state["words"][:3] == (halves[0::2] | (halves[1::2] << 16)).tolist()  # the pack's 3 words
    assert state["words"][3:] == [0] * 11

    geometry, fresnel, linear, display = (
        read_float(page, o, W, H) for o in ("geometry", "fresnel", "linear", "display")
    )
    NdotV, hit, _, _ = camera_rays(*state["orbit"], state["fov"], W, H)
    on = geometry[..., 1] > 0.5
    assert np.mean(on != hit) < 0.01  # silhouette pixels, a count, not precision
    model = on & (geometry[..., 2] == 0)
    assert model.sum() > 0.25 * W * H
    mu = geometry[..., 0]
    expected = rgb_fresnel_conductor(mu, state["eta"], n, k)
    err = np.abs(fresnel[..., :3][model] - expected[model]).max()
    assert err < FRESNEL, err
    # White sky, exposure 0: the radiance is F, the canvas its sRGB encoding.
    np.testing.assert_allclose(linear[..., :3][model], fresnel[..., :3][model], atol=1e-6)  # one product by 1.0
    np.testing.assert_allclose(display[..., :3][model], ACEScg_to_sRGB(expected[model]), atol=DISPLAY)
    # Split three ways: the model band stays the rgb-conductor, the reference
    # band is the measured copper it was fitted from (a distinct band).
    page.select_option("#compare", "all")
    geometry, fresnel = read_float(page, "geometry", W, H), read_float(page, "fresnel", W, H)
    mu = geometry[..., 0]
    on = geometry[..., 1] > 0.5
    eta = state["eta"]
    reference = curve_base_from_nk(library_material("Cu"), tuple(rgb_fit["eta_i_range"])).rgb(mu, eta)
    for kind, values in ((0, rgb_fresnel_conductor(mu, eta, n, k)), (2, reference)):
        band = on & (geometry[..., 2] == kind)
        assert band.sum() > 100
        np.testing.assert_allclose(fresnel[..., :3][band], values[band], atol=FRESNEL, rtol=FRESNEL)
    print(f"rgb-conductor mirror: max |GL - numpy| {err:.2e} over {model.sum()} pixels")


def test_rgb_conductor_rough_preview_and_refit(pages, live_server, rgb_fit):
    page = pages.new()
    open_rgb(page, live_server, rgb_fit)
    page.select_option("#environment", "studio")
    page.fill("#roughness", "0.45")
    page.dispatch_event("#roughness", "input")
    page.evaluate("window.cfPreview.ready()")
    page.wait_for_function("document.getElementById('preview').dataset.program === 'split-sum'")
    got = page.evaluate("window.cfPreview.readTables()")
    assert got["nodes"] == NODES
    table = np.asarray(got["albedo"], dtype=np.float64).reshape(3, NODES, 4)[..., :3]
    n, k = nk(rgb_fit)
    eta = page.evaluate("window.cfPreview.state.eta")
    expected = directional_albedo(MU, 0.45, lambda c: rgb_fresnel_conductor(c, eta, n, k))
    err = np.abs(table[0] - expected).max()
    assert err < TABLE, err
    # A pixel's albedo is its table at its cosine (linear in sqrt(NdotV)).
    geometry, fresnel = read_float(page, "geometry", W, H), read_float(page, "fresnel", W, H)
    model = (geometry[..., 1] > 0.5) & (geometry[..., 2] == 0)
    s = np.sqrt(geometry[..., 0][model])
    looked_up = np.stack([np.interp(s, np.sqrt(MU), table[0][:, c]) for c in range(3)], axis=-1)
    pixel_err = np.abs(fresnel[..., :3][model] - looked_up).max()
    assert pixel_err < EXACT, pixel_err
    print(f"rgb-conductor rough 0.45: table max err {err:.2e}, pixel vs table {pixel_err:.2e}")
    assert page.evaluate("window.cfPreview.gl.getError()") == 0

    # An edit refits it as an rgb-conductor (live while the key moves it, then full).
    page.locator("input[name=channel][value='2']").check()
    page.locator("circle.handle.c2[data-angle='50']").focus()
    page.keyboard.press("Shift+ArrowDown")
    page.wait_for_function(f"document.getElementById('fit-id').textContent !== '{rgb_fit['id']}'")
    page.wait_for_function(
        "!document.body.hasAttribute('aria-busy') && document.getElementById('preview-state').hidden"
    )
    refit = page.evaluate("fetch('/api/v1/fits/' + document.getElementById('fit-id').textContent).then(r => r.json())")
    assert refit["model"] == "rgb-conductor" and refit["base_fit_id"] == rgb_fit["id"]
    assert page.get_attribute("#preview", "data-fit") == refit["id"]
    assert page.get_attribute("#preview", "data-model") == "rgb-conductor"
