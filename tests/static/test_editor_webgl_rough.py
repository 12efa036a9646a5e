"""
The editor's rough and coated WebGL2 preview against numpy, in a real
Chromium (SwiftShader WebGL2) against a real server: the split-sum variant
of preview_shaders/glsl/shader_ball.frag and its albedo passes, the GGX
BRDF of cf_microfacet.glsl (both modes) compiled as GLSL ES 3.00, read back
from RGBA32F targets (EXT_color_buffer_float) and compared with
fitting.shading (microfacet, ibl) and the service's prefiltered slices at
sampled pixels; the controls change the image, roughness 0 is the smooth
sphere again, and a split sum out of reach leaves mirrors, said so.

Tolerances (float32 shaders against float64 numpy):

-   ``TABLE`` 1e-5: the albedo tables of the model, Lazanyi and the coat at
    their nodes, as the LUT's own parity (docs/shading.md,
    tests/preview_shaders/test_ibl_parity.py); measured 1.4e-7.
-   ``REFERENCE_TABLE`` 3e-4: the reference's table, a 2048-point sum over
    sampled microfacet normals. The same GLSL agrees with numpy to 2e-5 on
    Mesa (test_albedo_tables.py), but SwiftShader's sin and cos err by up to
    1.9e-4 (measured over [0, 2 pi]), which turns every sampled normal a
    little; the mean then moves by up to 1.3e-4 (measured, Au, roughness
    0.45), far below a visible difference.
-   ``EXACT`` 2e-6: a pixel against numpy of the same float32 inputs read
    back (the read-back table interpolated at the read-back cosine, the
    composition of read-back parts): only float32 rounding.
-   ``INTERPOLATION`` 2e-5: a pixel's albedo from its table against numpy's
    split sum at the pixel's own cosine: the table's 1e-5 plus its
    interpolation, linear in sqrt(NdotV) between 127 nodes that include the
    LUT's 64, which reproduces the LUT's lookup to 3e-8 (measured in numpy,
    Au, roughness 0.02 to 1); twice that for the coat and the metal added.
-   the prefiltered lighting against numpy's bilinear sample of the
    service's slices at the float64 mirror direction: 1e-5 of the slices'
    largest texel (float32 filtering and rounding), plus what an error of
    ``ACOS`` = 1e-4 rad in the shader's acos does to the lookup (SwiftShader's
    acos errs by up to 6.5e-5 rad, measured; atan by 3e-7): v moves by
    ACOS / pi of the height, times the largest step between neighbouring
    texels of the two layers used (:func:`light_tolerance`; 2.5e-4 at
    roughness 0.45 and 1.1e-3 at 0.2 in the studio, measured errors 8.7e-5
    and 3.5e-4).
-   ``BRDF`` 1e-5, as tests/preview_shaders/test_microfacet_parity.py:
    absolute below 1/sr, relative above.
"""

from __future__ import annotations

import loopback
import numpy as np
import pytest
from playwright.sync_api import expect
from editor_pages import (
    F32_BASE64,
    camera_rays,
    editor_url,  # noqa: F401 (a fixture)
    from_f32,
    open_editor,
    pages,  # noqa: F401 (a fixture)
    read_float,
    chromium,  # noqa: F401 (a fixture)
    live_server,  # noqa: F401 (a fixture)
)  # noqa: F401 (fixtures: one server and one Chromium a module)

from fitting import baseline_inputs, coated_conductor_model, curve_base_from_nk, library_material
from fitting.models.coated_conductor import collapse_to_eta_i
from fitting.optics.fresnel import fresnel_dielectric
from fitting.shading.ibl import (
    directional_albedo,
    split_sum_coated,
    split_sum_lazanyi,
    split_sum_model,
    split_sum_schlick,
)
from fitting.shading.microfacet import microfacet_brdf

pytestmark = [pytest.mark.server, pytest.mark.browser]

W, H = 96, 64
NODES = 127
MU = (np.arange(NODES) / (NODES - 1)) ** 2
TABLE = 1.0e-5
REFERENCE_TABLE = 3.0e-4
EXACT = 2.0e-6
INTERPOLATION = 2.0e-5
ACOS = 1.0e-4
BRDF = 1.0e-5


def read(page, output: str):
    """(H, W, 4) floats of OUTPUT.<output>, top row first."""
    return read_float(page, output, W, H)


def tables(page):
    """The albedo tables as integrated: (3, NODES, 3) model, Lazanyi, coat; (NODES, 3) reference."""
    got = page.evaluate("window.cfPreview.readTables()")
    assert got["nodes"] == NODES
    albedo = np.asarray(got["albedo"], dtype=np.float64).reshape(3, NODES, 4)[..., :3]
    return albedo, np.asarray(got["reference"], dtype=np.float64).reshape(NODES, 4)[..., :3]


def control(page, name, value):
    """Set a preview control as a person does, then wait for its split sum."""
    if isinstance(value, bool):
        page.set_checked(f"#{name}", value)
    else:
        page.fill(f"#{name}", str(value))
        page.dispatch_event(f"#{name}", "input")
    page.evaluate("window.cfPreview.lightingReady()")
    page.evaluate("new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done)))")
    assert page.evaluate("window.cfPreview.gl.getError()") == 0


def interp(table, mu):
    """A (NODES, 3) table at NdotV mu, linear in sqrt(mu) between the nodes
    (cf_albedo_table_lookup), per channel."""
    s = np.sqrt(np.clip(mu, 0.0, 1.0))
    return np.stack([np.interp(s, np.sqrt(MU), table[:, c]) for c in range(3)], axis=-1)


def slices(url, environment):
    response = loopback.get(f"{url}/api/v1/environments/{environment}/prefiltered", timeout=120)
    layers, height, width = (int(response.headers[f"x-texture-{k}"]) for k in ("layers", "height", "width"))
    return np.frombuffer(response.content, "<f4").reshape(layers, height, width, 3).astype(np.float64)


def prefiltered(S, R, roughness):
    """numpy of cf_prefiltered_lighting above the first node: GL's bilinear
    filtering of the two layers around the roughness (u repeats, v clamps),
    mixed linearly."""
    layers, height, width, _ = S.shape
    z = roughness * (layers - 1)
    j = min(int(np.floor(z)), layers - 2)
    assert j >= 1, "layer 0 is the analytic environment, which numpy does not have"
    Rn = R / np.linalg.norm(R, axis=-1, keepdims=True)
    u = 0.5 + np.arctan2(Rn[..., 0], -Rn[..., 2]) / (2.0 * np.pi)
    v = np.arccos(np.clip(Rn[..., 1], -1.0, 1.0)) / np.pi
    x, y = u * width - 0.5, v * height - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    i0, i1 = x0 % width, (x0 + 1) % width
    j0, j1 = np.clip(y0, 0, height - 1), np.clip(y0 + 1, 0, height - 1)

    def bilinear(layer):
        s = S[layer]
        return (1 - fy) * ((1 - fx) * s[j0, i0] + fx * s[j0, i1]) + fy * ((1 - fx) * s[j1, i0] + fx * s[j1, i1])

    t = z - j
    return (1.0 - t) * bilinear(j) + t * bilinear(j + 1)


def light_tolerance(S, roughness):
    """The bound on the lighting's error of the module docstring."""
    layers, height, _, _ = S.shape
    z = roughness * (layers - 1)
    j = min(int(np.floor(z)), layers - 2)
    step = [max(np.abs(np.diff(S[k], axis=0)).max(), np.abs(np.diff(S[k], axis=1)).max()) for k in (j, j + 1)]
    t = z - j
    return 1.0e-5 * S.max() + ACOS / np.pi * height * ((1.0 - t) * step[0] + t * step[1])


def fit_parameters(page, eta):
    fit_id = page.inner_text("#fit-id")
    fit = page.evaluate(f"fetch('/api/v1/fits/{fit_id}').then(r => r.json())")
    C = np.array([fit["coefficients"][p] for p in ("F0", "a", "alpha")], dtype=np.float64)
    p = collapse_to_eta_i(C, eta, tuple(fit["eta_i_range"]))[..., 0]
    return fit, C, (p[0], p[1], p[2])


def test_rough_and_coated_split_sum_match_numpy(pages, editor_url, live_server):
    page = pages.new()
    open_editor(page, editor_url)
    page.select_option("#compare", "all")
    page.select_option("#environment", "studio")
    control(page, "roughness", 0.45)
    state = page.evaluate(
        "(() => { const s = window.cfPreview.state;"
        " return {orbit: s.orbit, fov: s.fov, eta: s.eta, panels: s.panels}; })()"
    )
    assert state["panels"] == [0, 1, 2]
    assert page.get_attribute("#preview", "data-program") == "split-sum"
    eta, r = state["eta"], 0.45
    fit, C, params = fit_parameters(page, eta)
    nk = library_material("Au")
    b = baseline_inputs(nk)
    base = curve_base_from_nk(nk, tuple(fit["eta_i_range"]))

    # The albedo tables at their nodes: the numpy split sums of the same lobe.
    albedo, reference = tables(page)
    np.testing.assert_allclose(albedo[0], split_sum_model(MU, r, *params), atol=TABLE)
    np.testing.assert_allclose(albedo[1], split_sum_lazanyi(MU, r, eta, b["F0_air"], b["F82_air"]), atol=TABLE)
    expected_reference = directional_albedo(MU, r, lambda VdotH: base.rgb(VdotH, eta))
    np.testing.assert_allclose(reference, expected_reference, atol=REFERENCE_TABLE)

    geometry, fresnel, light, linear = (read(page, o) for o in ("geometry", "fresnel", "baseLight", "linear"))
    NdotV, hit, _, R = camera_rays(*state["orbit"], state["fov"], W, H)
    on = (geometry[..., 1] > 0.5) & hit
    mu = geometry[..., 0]
    direct = {0: split_sum_model(mu, r, *params), 1: split_sum_lazanyi(mu, r, eta, b["F0_air"], b["F82_air"]), 2: None}
    for k, table in enumerate((albedo[0], albedo[1], reference)):
        mask = on & (geometry[..., 2] == k)
        assert mask.sum() > 100
        np.testing.assert_allclose(fresnel[..., :3][mask], interp(table, mu[mask]), atol=EXACT)
        if direct[k] is not None:
            np.testing.assert_allclose(fresnel[..., :3][mask], direct[k][mask], atol=INTERPOLATION)
    # The lighting: the service's slices at the mirror direction, 0.45 between layers 3 and 4.
    S = slices(live_server, "studio")
    expected_light = prefiltered(S, R, r)
    np.testing.assert_allclose(light[..., :3][on], expected_light[on], atol=light_tolerance(S, r))
    assert light[..., :3][on].std() > 0.05  # the studio is lit unevenly
    np.testing.assert_allclose(linear[..., :3][on], (fresnel * light)[..., :3][on], rtol=EXACT, atol=1e-7)

    # A clear coat of eta_i seen from air, its own lobe at roughness 0.2.
    control(page, "coat", True)
    control(page, "coat-roughness", 0.2)
    rc = 0.2
    albedo, _ = tables(page)
    F0c = ((eta - 1.0) / (eta + 1.0)) ** 2
    np.testing.assert_allclose(albedo[2], split_sum_schlick(MU, rc, np.full(3, F0c)), atol=TABLE)
    coat, fresnel, light, coat_light, linear = (
        read(page, o) for o in ("coat", "fresnel", "baseLight", "coatLight", "linear")
    )
    mu = geometry[..., 0]
    mu_t = np.sqrt(1.0 - (1.0 - mu**2) / eta**2)
    np.testing.assert_allclose(coat[..., 2][on], mu_t[on], atol=EXACT)
    np.testing.assert_allclose(coat[..., 1][on], ((1.0 - fresnel_dielectric(mu, 1.0, eta)) ** 2)[on], atol=TABLE)
    np.testing.assert_allclose(coat[..., 0][on], interp(albedo[2], mu)[..., 0][on], atol=EXACT)
    model = on & (geometry[..., 2] == 0)
    np.testing.assert_allclose(fresnel[..., :3][model], interp(albedo[0], coat[..., 2])[model], atol=EXACT)
    np.testing.assert_allclose(fresnel[..., :3][model], split_sum_model(mu_t, r, *params)[model], atol=INTERPOLATION)
    np.testing.assert_allclose(coat_light[..., :3][on], prefiltered(S, R, rc)[on], atol=light_tolerance(S, rc))
    composed = coat[..., :1] * coat_light[..., :3] + coat[..., 1:2] * fresnel[..., :3] * light[..., :3]
    np.testing.assert_allclose(linear[..., :3][on], composed[on], rtol=EXACT, atol=1e-7)
    # The coat shows: its own reflection rises from F0 at the centre towards
    # the rim, and the metal is seen through it, never beyond asin(1 / eta_i).
    centre, rim = on & (mu > 0.95), on & (mu < 0.15)
    assert coat[..., 0][centre].max() < 0.06 and coat[..., 0][rim].min() > 0.15
    assert mu_t[on].min() >= np.sqrt(1.0 - 1.0 / eta**2) - EXACT

    # Under the white sky (radiance 1, so every slice is 1) the sphere is the
    # numpy coated split sum itself (fitting.shading.ibl.split_sum_coated).
    page.select_option("#environment", "white_sky")
    page.evaluate("window.cfPreview.lightingReady()")
    linear = read(page, "linear")
    expected = split_sum_coated(mu, r, *params, eta, rc)
    np.testing.assert_allclose(linear[..., :3][model], expected[model], atol=2 * INTERPOLATION)


def test_mirror_coat_and_the_way_back_to_smooth(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    page.select_option("#environment", "white_sky")
    smooth = read(page, "display")
    # Roughness 0 under a coat is still the mirror program: the exact
    # dielectric on top, the model at the cosine inside the coat.
    control(page, "coat", True)
    assert page.get_attribute("#preview", "data-program") == "mirror"
    state = page.evaluate(
        "({orbit: window.cfPreview.state.orbit, fov: window.cfPreview.state.fov, eta: window.cfPreview.state.eta})"
    )
    eta = state["eta"]
    fit, C, _ = fit_parameters(page, eta)
    geometry, coat, fresnel, linear = (read(page, o) for o in ("geometry", "coat", "fresnel", "linear"))
    on = geometry[..., 1] > 0.5
    mu = geometry[..., 0]
    mu_t = coat[..., 2]
    np.testing.assert_allclose(coat[..., 0][on], fresnel_dielectric(mu, 1.0, eta)[on], atol=TABLE)
    model = coated_conductor_model(mu_t, eta, C, tuple(fit["eta_i_range"]))
    band = on & (geometry[..., 2] == 0)
    assert band.sum() > 100
    np.testing.assert_allclose(fresnel[..., :3][band], model[band], atol=TABLE, rtol=TABLE)
    composed = coat[..., :1] + coat[..., 1:2] * fresnel[..., :3]
    np.testing.assert_allclose(linear[..., :3][on], composed[on], rtol=EXACT, atol=1e-7)
    # Seen through the coat the metal never shows its grazing angles: the
    # cosine inside stays above sqrt(1 - 1 / eta^2).
    assert mu_t[on].min() >= np.sqrt(1.0 - 1.0 / eta**2) - EXACT

    # Rough and back: roughness 0 without the coat is today's smooth sphere, bit for bit.
    control(page, "roughness", 0.6)
    assert page.get_attribute("#preview", "data-program") == "split-sum"
    control(page, "roughness", 0)
    control(page, "coat", False)
    assert page.get_attribute("#preview", "data-program") == "mirror"
    np.testing.assert_array_equal(read(page, "display"), smooth)


def brdf_grid(page, mode, roughness, F0, a, alpha, eta_i=1.0, coat_roughness=0.0, phi=np.pi, n=64):
    """cf_microfacet_immersed / _coated (microfacet.frag, GLSL ES 3.00) over
    n x n view x light angles in [0, 1.5] rad: the BRDF, V and L."""
    got = page.evaluate(
        """async ([mode, grid, phi, uniforms, n]) => {
            """
        + F32_BASE64
        + """
            const { fullscreenProgram, floatTarget, drawInto, readTarget } = await import('/glpass.js');
            const gl = window.cfPreview.gl;
            const pass = await fullscreenProgram(gl, 'microfacet.frag', { CF_MODE: mode });
            const u = pass.uniforms;
            gl.useProgram(pass.program);
            gl.uniform4f(u.u_grid, ...grid);
            gl.uniform1f(u.u_phi, phi);
            for (const [name, value] of Object.entries(uniforms)) {
                if (Array.isArray(value)) gl.uniform3f(u[name], ...value);
                else gl.uniform1f(u[name], value);
            }
            const targets = [0, 1, 2].map(() => floatTarget(gl, n, n));
            drawInto(gl, window.cfPreview.vao, targets, n, n);
            const out = targets.map((t) => f32(readTarget(gl, t, n, n)));
            targets.forEach((t) => gl.deleteTexture(t));
            return { out, error: gl.getError() };
        }""",
        [
            0 if mode == "immersed" else 1,
            [0.0, 1.5 / (n - 1), 0.0, 1.5 / (n - 1)],
            float(phi),
            {
                "cf_F0": list(F0),
                "cf_a": list(a),
                "cf_alpha": list(alpha),
                "cf_roughness": roughness,
                "cf_eta_i": eta_i,
                "cf_coat_roughness": coat_roughness,
            },
            n,
        ],
    )
    assert got["error"] == 0
    f, V, L = (from_f32(x).reshape(n, n, 4)[..., :3] for x in got["out"])
    return f, V, L


def test_microfacet_brdf_in_webgl_matches_numpy(pages, editor_url):
    page = pages.new()
    open_editor(page, editor_url)
    F0, a, alpha = (0.37, 0.38, 0.39), (0.6, 0.55, 0.0), (4.8, 4.8, 5.0)  # Cr at eta_i 1.5, rounded

    def error(f, expected):
        return float((np.abs(f - expected) / np.maximum(1.0, np.abs(expected))).max())

    for roughness in (0.05, 0.3, 1.0):
        for phi in (np.pi, 0.4):
            f, V, L = brdf_grid(page, "immersed", roughness, F0, a, alpha, phi=phi)
            expected = microfacet_brdf(V, L, roughness, F0, a, alpha)
            assert np.all(np.isfinite(f)) and expected.max() > 0.1
            assert error(f, expected) <= BRDF, (roughness, phi)
    for eta_i, roughness, coat_roughness in ((1.5, 0.3, 0.1), (2.5, 0.6, 0.5), (1.0, 0.4, 0.2)):
        f, V, L = brdf_grid(page, "coated", roughness, F0, a, alpha, eta_i, coat_roughness, phi=1.0)
        expected = microfacet_brdf(V, L, roughness, F0, a, alpha, "coated", eta_i, coat_roughness)
        assert error(f, expected) <= BRDF, (eta_i, roughness, coat_roughness)
    # The test sees a changed roughness.
    f, V, L = brdf_grid(page, "immersed", 0.3, F0, a, alpha)
    assert error(f, microfacet_brdf(V, L, 0.3001, F0, a, alpha)) > BRDF


def test_controls_change_the_image(pages, editor_url):
    pages.expected.append("503")  # the refused prefiltered environment below
    page = pages.new()
    open_editor(page, editor_url)
    page.select_option("#environment", "studio")
    # Every new control explains itself.
    for label in ("roughness", "coat", "coat-roughness"):
        assert len(page.get_attribute(f"label[for={label}]", "title")) > 60
    assert page.is_disabled("#coat-roughness")
    views = {"smooth": read(page, "display")}
    control(page, "roughness", 0.5)
    assert page.inner_text("#roughness-value") == "0.50"
    views["rough"] = read(page, "display")
    control(page, "coat", True)
    assert not page.is_disabled("#coat-roughness")
    views["coated"] = read(page, "display")
    control(page, "coat-roughness", 0.7)
    assert page.inner_text("#coat-roughness-value") == "0.70"
    views["rough coat"] = read(page, "display")
    names = list(views)
    for i, first in enumerate(names):
        for second in names[i + 1 :]:
            assert np.abs(views[first] - views[second]).max() > 0.02, (first, second)
    # The rough sphere is blurred: its neighbouring pixels differ less.
    on = read(page, "geometry")[..., 1] > 0.5

    def roughness_of(image):  # noqa: E306
        return np.abs(np.diff(image[..., :3], axis=1))[on[:, 1:] & on[:, :-1]].mean()

    assert roughness_of(views["rough"]) < 0.7 * roughness_of(views["smooth"])
    assert page.is_hidden("#preview-lighting")

    # A split sum out of reach (the service refuses the slices): every lobe
    # is drawn as a mirror, and the page says so.
    other = pages.new()
    other.route(
        "**/api/v1/environments/**",
        lambda route: route.fulfill(status=503, content_type="application/json", body='{"detail": "no GL driver"}'),
    )
    open_editor(other, editor_url)
    other.select_option("#environment", "studio")
    other.fill("#roughness", "0.5")
    other.dispatch_event("#roughness", "input")
    other.wait_for_selector("#preview-lighting:not([hidden])")
    # The note shows "Preparing the rough lighting..." until the 503 arrives: wait for its text.
    expect(other.locator("#preview-lighting")).to_contain_text("no GL driver")
    assert other.get_attribute("#preview", "data-program") == "mirror"
    np.testing.assert_array_equal(read(other, "display"), views["smooth"])
