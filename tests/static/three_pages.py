"""
The three.js example page (/examples/three.html) against the editor's WebGL
preview and the physics, in one Chromium page (import it: ``from
three_pages import measure_three``); shared by
tests/static/test_three_material.py and benchmarks/three_parity.py.

:func:`serve` (a quiet http.server on 127.0.0.1 serving one folder) is also
the three.js package's and the node material's static site.

Set-up, the same for both renders: an environment of the preview, the
white sky (radiance 1 in every direction, so that the two environment
filters, the project's prefiltered slices and three's PMREM, drop out and
what is compared is the material) or the studio or the outdoor sky (the
same cf_environment.glsl on both sides: three draws it into a 1024 x 512
equirect and prefilters it with its PMREM, the preview evaluates it per
pixel for a mirror and reads the project's prefiltered slices for a rough
lobe, so there the figures hold the two filters' difference too; and three
multiplies albedo by radiance per channel in its working space, linear
Rec.709, where the preview does in ACEScg: for a coloured sky that is most
of the difference, so :func:`preview_lit_in_rec709` recomposes the
preview's own parts as three lights them, ``preview_rec709``), the
preview's camera (orbit (0.5, 0.25, 4.2), vertical field of view 0.52
rad) at W x H pixels, a clear coat of index eta_i over the metal. Both read
back as float32 linear radiance: the preview in ACEScg (OUTPUT.linear),
three in linear Rec.709 (its working space), converted back to ACEScg with
the inverse of the very matrix the shader used (CF_ACESCG_TO_SRGB).

Pixels compared: on the ball in both, with NdotV >= :data:`NDOTV_MIN` (the
outermost pixels differ by geometry alone: three rasterises a 256 x 128
sphere mesh, the preview intersects the exact sphere). The centre is
NdotV >= :data:`CENTRE`, the ring near grazing NdotV in :data:`RING`.

Several settings are measured on one page load (the example page relights
its balls with ``cfThree.setEnvironment``, sets the material's roughness
per read-back, and the preview's ball is made once per page).

The full air-coat-metal stack: under the white sky the ball's radiance is
the directional albedo of the coated metal seen from air (:func:`coated_albedo`),

    E_c(mu) + 1/2 sum_{x = s, p} [1 - R_x(mu)]^2 E_m(mu_t) / [1 - R_x(mu) E_m(mu_t)],

the coat's own lobe E_c (the exact dielectric for a mirror coat, Schlick's
split sum at the coat's F0 for a rough one), the coat's reflectance R_x of
each polarisation at the view angle, and the metal's lobe E_m at the cosine
inside the coat mu_t: at roughness 0 its Fresnel, where the sum is exactly
fitting.optics.coated_stack.coated_stack_from_metal; for a rough metal
its GGX lobe's parts (fitting.shading.coated_layer: what leaves at once,
what returns over the hemisphere), the plugin's approximation
(docs/gltf/EXT_materials_coated_conductor/).
``composed`` is the fit's own model (numpy, fitting.models.kinds) through
that stack, what the plugin must draw; ``physics`` the 1 nm spectral
reference under the coat through it.
"""

from __future__ import annotations

import functools
import http.server
import threading
from contextlib import contextmanager
from pathlib import Path

import loopback
import numpy as np
import pytest
from editor_pages import F32_BASE64, Pages, camera_rays, from_f32

from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import reference_ACEScg_grid
from fitting.models.kinds import model_kind
from fitting.optics.coated_stack import refracted_cos
from fitting.optics.fresnel import fresnel_dielectric
from fitting.shading.coated_layer import (
    escape_fraction,
    hemispherical_albedo,
    internal_reflectance,
    seen_base,
    through_coat,
)
from fitting.shading.ibl import split_sum_schlick
from preview_shaders.display import ACEScg_to_sRGB_matrix

W, H = 128, 128
ORBIT, FOV = (0.5, 0.25, 4.2), 0.52
NDOTV_MIN = 0.1
CENTRE = 0.97
RING = (0.1, 0.25)
_NODES = np.linspace(0.0, 1.0, 65) ** 2  # the physics' NdotV nodes, interpolated per pixel


def create_fit(server: str, material: str, model: str) -> dict:
    """POST /api/v1/fits for a library material and kind; the FitPublic answer."""
    response = loopback.post(f"{server}/api/v1/fits", json={"material": material, "model": model}, timeout=300)
    response.raise_for_status()
    return response.json()


def open_example(page, server: str, fit_id: str, eta_i: float, env: str = "white_sky") -> None:
    page.goto(f"{server}/examples/three.html?fit={fit_id}&eta_i={eta_i}&env={env}")
    page.wait_for_function("document.body.dataset.ready")
    state = page.evaluate("document.body.dataset.ready")
    assert state == "true", page.evaluate("document.getElementById('status').textContent")


class ExamplePage:
    """
    One example page for a test module: loaded with the first fit shown
    (:func:`open_example`), then each other put on it (:func:`show_fit`),
    so that each environment is prefiltered once a module; ``errors``: what
    the page logged (uncaught errors, console errors: ``editor_pages.Pages``'s list).
    """

    def __init__(self, page, server: str, errors: list[str]) -> None:
        self.page, self.server, self.errors = page, server, errors
        self.open: tuple[str, float] | None = None

    def show(self, fit_id: str, eta_i: float):
        """The page showing fit ``fit_id`` at ``eta_i``."""
        if self.open is None:
            open_example(self.page, self.server, fit_id, eta_i)
        elif self.open != (fit_id, eta_i):
            show_fit(self.page, fit_id, eta_i)
        self.open = (fit_id, eta_i)
        return self.page

    @contextmanager
    def no_new_errors(self):
        """Fails if the page logs an error inside the block."""
        before = len(self.errors)
        yield
        assert self.errors[before:] == []


@contextmanager
def example_page(chromium, server: str, cls=ExamplePage):
    """
    A :class:`ExamplePage` (or ``cls``) on a page of ``editor_pages.Pages``
    (a context of its own, its errors recorded), closed at the end (before
    the server stops).
    """
    pages = Pages(chromium)
    try:
        yield cls(pages.new(900, 700), server, pages.errors)
    finally:
        for context in pages.contexts:
            context.close()


def show_fit(page, fit_id: str, eta_i: float) -> None:
    """
    Put another fit's export on the open example page's balls
    (``cfThree.setFit``, no reload: its environments stay prefiltered, the
    page's slowest step in SwiftShader) and check that they show it.
    """
    page.evaluate("([id, eta]) => window.cfThree.setFit(id, eta)", [fit_id, eta_i])
    assert page.evaluate("window.cfThree.fit") == {"id": fit_id, "etaI": eta_i}
    shown = page.evaluate("window.cfThree.balls.model.material.userData.coatedConductor.coatIor")
    assert shown == pytest.approx(eta_i), (shown, eta_i)


def three_ACEScg(page, which: str, roughness: float, coat_roughness: float) -> tuple[np.ndarray, np.ndarray]:
    """(H, W, 3) linear ACEScg of ball ``which`` (model or fallback), top row first, and its mask."""
    flat = page.evaluate(
        f"([which, w, h, s]) => {{ {F32_BASE64} return f32(window.cfThree.readFloat(which, w, h, s)); }}",
        [which, W, H, {"roughness": roughness, "clearcoatRoughness": coat_roughness}],
    )
    pixels = from_f32(flat).reshape(H, W, 4)[::-1]
    rec709 = pixels[..., :3]
    return rec709 @ np.linalg.inv(ACEScg_to_sRGB_matrix()).T, pixels[..., 3] > 0.5


def set_environment(page, env: str) -> None:
    """Relight the example page's balls by ``env`` (room, white_sky, studio, outdoor) unless they are."""
    if page.evaluate("window.cfThree.environment") != env:
        page.evaluate("(env) => window.cfThree.setEnvironment(env)", env)


def preview_ACEScg(
    page, fit: dict, eta_i: float, roughness: float, coat_roughness: float, env: str = "white_sky"
) -> np.ndarray:
    """(H, W, 3) linear ACEScg of the editor's preview (static/preview.js) at the same settings (one ball a page)."""
    flat = page.evaluate(
        """async ([fit, eta, roughness, coatRoughness, env, orbit, fov, w, h]) => {
            """
        + F32_BASE64
        + """
            const { ShaderBall, OUTPUT, ENVIRONMENT } = await import('/preview.js');
            if (!window.cfParityBall) {
                const canvas = document.createElement('canvas');
                Object.assign(canvas.style, { width: w + 'px', height: h + 'px' });
                document.body.appendChild(canvas);
                window.cfParityBall = ShaderBall.create(canvas, null);
            }
            const ball = await window.cfParityBall;
            ball.setFit(fit);
            ball.set({ eta, roughness, coated: true, coatRoughness, environment: ENVIRONMENT[env], orbit, fov });
            await ball.ready();
            return f32(ball.readFloat(OUTPUT.linear, w, h));
        }""",
        [fit, eta_i, roughness, coat_roughness, env, list(ORBIT), FOV, W, H],
    )
    return from_f32(flat).reshape(H, W, 4)[::-1][..., :3]


def base_through_coat(E: np.ndarray, NdotV: np.ndarray, fit: dict, eta_i: float, roughness: float) -> np.ndarray:
    """
    The metal's albedo ``E`` (H, W, 3) at each pixel's in-coat cosine seen
    from air at ``NdotV`` (H, W) through the coat with the bounces
    (fitting.shading.coated_layer.through_coat): for a rough metal with the
    fit's own lobe parts (its escape fraction, per pixel by the physics'
    nodes, and its hemispherical albedo), as the plugin's escape table.
    """
    mu = np.clip(np.nan_to_num(NdotV), 0.0, 1.0)
    flat = E.reshape(-1, 3)
    if roughness > 0:
        fresnel = fit_fresnel(fit, eta_i)
        q = per_pixel(escape_fraction(refracted_cos(_NODES, eta_i), roughness, fresnel, eta_i), mu).reshape(-1, 3)
        E_bar, r_bar = hemispherical_albedo(roughness, fresnel), internal_reflectance(eta_i)
    else:
        q, E_bar, r_bar = np.ones_like(flat), np.zeros(3), 0.0
    return through_coat(flat, q, E_bar, r_bar, mu.reshape(-1), eta_i, roughness).reshape(E.shape)


def preview_lit_in_rec709(page, NdotV: np.ndarray, fit: dict, eta_i: float, roughness: float) -> np.ndarray:
    """
    (H, W, 3) linear ACEScg: the preview ball's last settings lit as three
    lights them, the products of albedo and radiance taken per channel in
    linear Rec.709 (three's working space) rather than in ACEScg (the
    preview's), and the base composed with the full stack (the bounces
    between coat and metal, which the preview leaves out):
    M^-1 [E_c M L_c + M S(F) M L_m] from the preview's own parts (the
    metal's albedo F, lightings L_m and L_c, coat albedo E_c), S
    :func:`base_through_coat` at each pixel's ``NdotV``, M = CF_ACESCG_TO_SRGB.
    """
    flat = page.evaluate(
        """async ([w, h]) => {
            """
        + F32_BASE64
        + """
            const { OUTPUT } = await import('/preview.js');
            const ball = await window.cfParityBall;
            return ['fresnel', 'baseLight', 'coatLight', 'coat'].map((o) => f32(ball.readFloat(OUTPUT[o], w, h)));
        }""",
        [W, H],
    )
    F, base, coat_light, coat = (from_f32(f).reshape(H, W, 4)[::-1] for f in flat)
    M = ACEScg_to_sRGB_matrix()
    E = coat[..., :1]
    seen = base_through_coat(F[..., :3], NdotV, fit, eta_i, roughness)
    rec709 = E * (coat_light[..., :3] @ M.T) + (seen @ M.T) * (base[..., :3] @ M.T)
    return rec709 @ np.linalg.inv(M).T


def coated_albedo(metal_fresnel, eta_i: float, roughness: float, coat_roughness: float) -> np.ndarray:
    """
    The coated metal's directional albedo seen from air at the physics'
    NdotV nodes, (n, 3) linear ACEScg: the coat's lobe E_c and the metal's
    lobe (``metal_fresnel(cos) -> (..., 3)`` the metal under the coat)
    through the coat with the bounces (fitting.shading.coated_layer.seen_base);
    for mirrors the full stack exactly.
    """
    mu = _NODES
    F0c = ((eta_i - 1.0) / (eta_i + 1.0)) ** 2
    coat = (
        fresnel_dielectric(mu, 1.0, eta_i)[:, None]
        if coat_roughness == 0
        else split_sum_schlick(mu, coat_roughness, np.full(3, F0c))
    )
    return coat + seen_base(mu, eta_i, roughness, metal_fresnel)


def fit_fresnel(fit: dict, eta_i: float):
    """The fit's own model (numpy, its kind's evaluation) under a coat of ``eta_i``: cos -> (..., 3) ACEScg."""
    kind = model_kind(fit["model"])
    C = np.asarray([fit["coefficients"][p] for p in kind.parameters], dtype=np.float64)
    return lambda c: kind.evaluate(np.asarray(c), eta_i, C, tuple(fit["eta_i_range"]))


def per_pixel(nodes_rgb: np.ndarray, NdotV: np.ndarray) -> np.ndarray:
    """A curve over the physics' nodes at each pixel's NdotV (linear in sqrt(NdotV))."""
    s = np.sqrt(NdotV)
    return np.stack([np.interp(s, np.sqrt(_NODES), nodes_rgb[:, c]) for c in range(3)], axis=-1)


def _stats(dE: np.ndarray, NdotV: np.ndarray, region: np.ndarray) -> dict:
    centre, ring = region & (NdotV >= CENTRE), region & (NdotV >= RING[0]) & (NdotV <= RING[1])
    return {
        "mean": float(dE[region].mean()),
        "p99": float(np.percentile(dE[region], 99)),
        "max": float(dE[region].max()),
        "centre": float(dE[centre].mean()),
        "ring": float(dE[ring].mean()),
    }


def measure_three(
    page, server: str, nk, fit: dict, eta_i: float, roughness: float, coat_roughness: float, env: str = "white_sky"
) -> dict:
    """
    Delta E 2000 figures ({mean, p99, max, centre, ring} each) of the
    three.js ball through the plugin under ``env`` against the editor's
    WebGL preview at the same settings as it draws (``preview``; under the
    white sky ``preview_bare``) and its parts composed as three lights them
    with the full stack (``preview_rec709``; under the white sky
    ``preview``); under the white sky also against the fit's own model
    through the full stack in numpy (``composed``), the physics
    (``physics``), the fit's own error there (``fit_vs_physics``: composed
    against physics) and the fallback ball against the physics
    (``fallback``). The example page must be open on ``fit`` at ``eta_i``.
    """
    set_environment(page, env)
    NdotV, hit, _, _ = camera_rays(*ORBIT, FOV, W, H, bands=1)
    three, three_mask = three_ACEScg(page, "model", roughness, coat_roughness)
    preview = preview_ACEScg(page, fit, eta_i, roughness, coat_roughness, env)
    if env != "white_sky":  # the preview alone, as it draws and lit in three's working space
        region = hit & three_mask & (NdotV >= NDOTV_MIN)
        in_rec709 = preview_lit_in_rec709(page, NdotV, fit, eta_i, roughness)
        return {
            "pixels": int(region.sum()),
            "preview": _stats(delta_E_map(preview, three), NdotV, region),
            "preview_rec709": _stats(delta_E_map(in_rec709, three), NdotV, region),
            "centre_rgb": three[region & (NdotV >= CENTRE)].mean(axis=0).tolist(),
        }
    fallback, fallback_mask = three_ACEScg(page, "fallback", roughness, coat_roughness)
    region = hit & three_mask & fallback_mask & (NdotV >= NDOTV_MIN)
    figures = {
        "pixels": int(region.sum()),
        "preview_bare": _stats(delta_E_map(preview, three), NdotV, region),
        "preview": _stats(delta_E_map(preview_lit_in_rec709(page, NdotV, fit, eta_i, roughness), three), NdotV, region),
        "centre_rgb": three[region & (NdotV >= CENTRE)].mean(axis=0).tolist(),
        "fallback_centre_rgb": fallback[region & (NdotV >= CENTRE)].mean(axis=0).tolist(),
    }
    # The 1 nm reference through its product-grid kernel (one eta_i, every cosine the quadrature
    # asks for), which is reference_ACEScg to 1.3e-13 per channel (tests/fitting/colour/
    # test_reference_grid.py) at about an eighth of the cost.
    physics = per_pixel(
        coated_albedo(
            lambda c: reference_ACEScg_grid(nk, np.asarray(c).reshape(-1), [eta_i])[0].reshape(np.shape(c) + (3,)),
            eta_i,
            roughness,
            coat_roughness,
        ),
        NdotV,
    )
    figures["physics"] = _stats(delta_E_map(physics, three), NdotV, region)
    figures["fallback"] = _stats(delta_E_map(physics, fallback), NdotV, region)
    composed = per_pixel(coated_albedo(fit_fresnel(fit, eta_i), eta_i, roughness, coat_roughness), NdotV)
    figures["composed"] = _stats(delta_E_map(composed, three), NdotV, region)
    figures["fit_vs_physics"] = _stats(delta_E_map(physics, composed), NdotV, region)
    return figures


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


@contextmanager
def serve(root: Path):
    """http.server on 127.0.0.1 serving ``root`` only: its URL."""
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(root)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
