"""
The Babylon.js example page (/examples/babylon.html) against the three.js
example page (/examples/three.html), two pages of one Chromium (import it:
``from babylon_pages import measure_babylon``); shared by
tests/static/test_babylon_material.py and benchmarks/babylon_parity.py.

Set-up, the same for both renders: the same fit's glTF export at the same
coat index, each loaded by its renderer's own loader with its own plugin
(coated-conductor-three's GLTFLoader plugin, coated-conductor-babylon's
glTF loader extension), a uniform white sky (radiance 1 in every
direction: each pixel shows the coated metal's directional albedo at its
NdotV, and neither renderer's environment filter changes it), the three.js
example's camera (orbit (0.5, 0.25, 4.2), vertical field of view 0.52 rad)
at W x H pixels on a unit sphere mesh of each renderer's own. Both read back
as float32 linear Rec.709, converted to ACEScg with the inverse of
CF_ACESCG_TO_SRGB, and compared with Delta E 2000 per pixel over the
pixels on the ball in both with NdotV >= NDOTV_MIN (three_pages's region:
the outermost pixels differ by the two meshes alone), its centre and the
ring near grazing as there.
"""

from __future__ import annotations

import numpy as np
from editor_pages import F32_BASE64, camera_rays, from_f32
from three_pages import CENTRE, FOV, H, NDOTV_MIN, ORBIT, RING, W, _stats, three_ACEScg

from fitting.colour.delta_e import delta_E_map
from preview_shaders.display import ACEScg_to_sRGB_matrix


def open_babylon(page, server: str, fit_id: str, eta_i: float) -> None:
    page.goto(f"{server}/examples/babylon.html?fit={fit_id}&eta_i={eta_i}")
    page.wait_for_function("document.body.dataset.ready")
    state = page.evaluate("document.body.dataset.ready")
    assert state == "true", page.evaluate("document.getElementById('status').textContent")


def show_babylon(page, server: str, fit_id: str, eta_i: float) -> None:
    """The Babylon page showing fit ``fit_id`` at ``eta_i`` (loaded once, then ``cfBabylon.setFit``)."""
    if page.evaluate("window.cfBabylon === undefined"):
        open_babylon(page, server, fit_id, eta_i)
    else:
        page.evaluate("([id, eta]) => window.cfBabylon.setFit(id, eta)", [fit_id, eta_i])
    shown = page.evaluate("window.cfBabylon.fit")
    assert shown == {"id": fit_id, "etaI": eta_i}, shown


def babylon_ACEScg(page, roughness: float, coat_roughness: float) -> tuple[np.ndarray, np.ndarray]:
    """(H, W, 3) linear ACEScg of the Babylon ball, top row first, and its mask."""
    flat = page.evaluate(
        f"async ([w, h, s]) => {{ {F32_BASE64} return f32(await window.cfBabylon.readFloat(w, h, s)); }}",
        [W, H, {"roughness": roughness, "clearCoatRoughness": coat_roughness}],
    )
    pixels = from_f32(flat).reshape(H, W, 4)[::-1]
    return pixels[..., :3] @ np.linalg.inv(ACEScg_to_sRGB_matrix()).T, pixels[..., 3] > 0.5


def measure_babylon(three_page, babylon_page) -> dict:
    """
    Delta E 2000 statistics of the Babylon ball against the three ball
    (both pages showing the same fit and coat index under the white sky),
    both smooth (metal and coat roughness 0, whatever the export's):
    ``babylon_vs_three`` (mean, p99, max, centre, ring), ``pixels``, and
    the centre's mean ACEScg of each.
    """
    three, three_mask = three_ACEScg(three_page, "model", 0.0, 0.0)
    babylon, babylon_mask = babylon_ACEScg(babylon_page, 0.0, 0.0)
    NdotV, hit, _, _ = camera_rays(*ORBIT, FOV, W, H, bands=1)
    region = hit & three_mask & babylon_mask & (NdotV >= NDOTV_MIN)
    centre = region & (NdotV >= CENTRE)
    ring = region & (NdotV >= RING[0]) & (NdotV <= RING[1])
    return {
        "pixels": int(region.sum()),
        "babylon_vs_three": _stats(delta_E_map(three, babylon), NdotV, region),
        "three_centre_rgb": three[centre].mean(axis=0).tolist(),
        "babylon_centre_rgb": babylon[centre].mean(axis=0).tolist(),
        "three_ring_rgb": three[ring].mean(axis=0).tolist(),
        "babylon_ring_rgb": babylon[ring].mean(axis=0).tolist(),
    }


__all__ = ["babylon_ACEScg", "measure_babylon", "open_babylon", "show_babylon"]
