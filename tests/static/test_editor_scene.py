"""
"Your scene" in the editor (static/editor/scene_view.js): the fit on
screen drawn by three.js and the project's package on a mesh and under an
environment the artist uploads, read back from the canvas in Chromium
(SwiftShader WebGL2). The files are written here: a box as a glTF binary
(positions, normals, indices), a Radiance .hdr (RGBE, flat scanlines) of
one colour and an OpenEXR image of another (Mitsuba's Bitmap writes it).
Checked: the built-in sphere draws the fit; an uploaded box changes the
silhouette; an uploaded red sky (.hdr) turns the reflection red and a
green one (.exr) green; a silver fit is less yellow than the gold one; a
drag orbits and the wheel zooms; files that are not what they say and a
wrong extension give a message and leave the scene drawn; nothing is sent
to the server.

Cost: one editor page (one extra fit, Ag), three's modules and a few
PMREM passes at the canvas's size.
"""

from __future__ import annotations

import base64
import json
import math
import struct
import tempfile
from pathlib import Path

import numpy as np
import pytest
from editor_pages import chromium, editor_url, live_server, open_editor, pages, settled  # noqa: F401 (fixtures)
from playwright.sync_api import expect

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def box_glb(half=(1.0, 0.35, 0.6)) -> bytes:
    """A box (24 vertices, 12 triangles, flat normals) as a glTF 2.0 binary."""
    positions, normals, indices = [], [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = [a for a in range(3) if a != axis]
            base = len(positions)
            for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = sign * half[axis], du * half[u], dv * half[v]
                n = [0.0, 0.0, 0.0]
                n[axis] = sign
                positions.append(p)
                normals.append(n)
            quad = [0, 1, 2, 0, 2, 3] if (sign > 0) == ((axis % 2) == 0) else [0, 2, 1, 0, 3, 2]
            indices += [base + i for i in quad]
    pos = np.asarray(positions, "<f4")
    binary = pos.tobytes() + np.asarray(normals, "<f4").tobytes() + np.asarray(indices, "<u2").tobytes()
    binary += b"\0" * (-len(binary) % 4)
    n_vertices = len(positions)
    document = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12 * n_vertices},
            {"buffer": 0, "byteOffset": 12 * n_vertices, "byteLength": 12 * n_vertices},
            {"buffer": 0, "byteOffset": 24 * n_vertices, "byteLength": 2 * len(indices)},
        ],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": n_vertices,
                "type": "VEC3",
                "min": pos.min(0).tolist(),
                "max": pos.max(0).tolist(),
            },
            {"bufferView": 1, "componentType": 5126, "count": n_vertices, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        ],
    }
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(binary), b"BIN\0") + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def rgbe_hdr(colour, width=16, height=8) -> bytes:
    """A Radiance .hdr of one linear colour everywhere (RGBE, flat scanlines)."""
    top = max(colour)
    mantissa, exponent = math.frexp(top)
    scale = mantissa * 256.0 / top
    pixel = bytes([int(c * scale) for c in colour] + [exponent + 128])
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode()
    return header + pixel * (width * height)


def exr_sky(colour, width=16, height=8) -> bytes:
    """An OpenEXR image of one linear colour everywhere (float RGB), written by Mitsuba's Bitmap (OpenEXR inside)."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sky.exr"
        mi.Bitmap(np.broadcast_to(np.asarray(colour, np.float32), (height, width, 3)).copy()).write(str(path))
        return path.read_bytes()


def pixels(page) -> np.ndarray:
    got = page.evaluate("() => window.cfScene.pixels()")
    data = np.frombuffer(base64.b64decode(got["base64"]), dtype=np.uint8)
    return data.astype(np.float64).reshape(got["height"], got["width"], 4)


def upload(page, selector, name, data, mime="application/octet-stream"):
    page.set_input_files(selector, files=[{"name": name, "mimeType": mime, "buffer": data}])


def drawn(page, text):
    """Wait until the scene is drawn and its status names `text`."""
    page.wait_for_function(
        "(text) => document.getElementById('scene').dataset.state === 'ready'"
        " && document.getElementById('scene-status').textContent.includes(text)",
        arg=text,
    )


def colour_of(image, mask):
    return image[..., :3][mask].mean(axis=0)


def test_your_mesh_under_your_environment(pages, editor_url):
    page = pages.new(1400, 900)
    requests = []
    page.on("request", lambda r: requests.append(r.url))
    open_editor(page, editor_url)
    gold = settled(page)
    page.click("#scene summary")
    drawn(page, "sphere under room")
    expect(page.locator("#scene")).to_have_attribute("data-fit", gold)
    sphere = pixels(page)
    sphere_mask = sphere[..., 3] > 0
    assert sphere_mask.mean() > 0.05
    r, g, b = colour_of(sphere, sphere_mask)
    assert r > b * 1.3  # gold

    # The mesh: a flat box, its own silhouette, the same material.
    upload(page, "#scene-mesh", "box.glb", box_glb(), "model/gltf-binary")
    drawn(page, "box.glb under room")
    box = pixels(page)
    box_mask = box[..., 3] > 0
    union = (box_mask | sphere_mask).sum()
    assert box_mask.mean() > 0.05 and (box_mask & sphere_mask).sum() / union < 0.8
    r, g, b = colour_of(box, box_mask)
    assert r > b * 1.3

    # Orbit: a drag turns the box (another silhouette); the wheel zooms in (a larger one).
    page.locator("#scene-canvas").scroll_into_view_if_needed()
    area = page.locator("#scene-canvas").bounding_box()
    cx, cy = area["x"] + area["width"] / 2, area["y"] + area["height"] / 2
    page.mouse.move(cx, cy)
    page.mouse.down()
    page.mouse.move(cx + area["width"] / 4, cy + 10, steps=5)
    page.mouse.up()
    turned = pixels(page)[..., 3] > 0
    assert (turned != box_mask).mean() > 0.02
    distance = "() => window.cfScene.three.camera.position.distanceTo(window.cfScene.three.controls.target)"
    before = page.evaluate(distance)
    page.mouse.wheel(0, -400)
    page.wait_for_function(f"({distance})() < {before} * 0.95")
    closer = pixels(page)[..., 3] > 0
    assert closer.mean() > turned.mean() * 1.1

    # The environment: a red sky everywhere; the reflection turns red.
    upload(page, "#scene-environment", "red.hdr", rgbe_hdr((1.0, 0.02, 0.02)))
    drawn(page, "box.glb under red.hdr")
    red = pixels(page)
    mask = red[..., 3] > 0
    r, g, b = colour_of(red, mask)
    assert r > 3 * g and r > 3 * b

    # An OpenEXR environment (three's EXRLoader): a green sky, the reflection turns green.
    exr = exr_sky((0.02, 1.0, 0.02))
    assert exr[:4] == b"\x76\x2f\x31\x01"  # OpenEXR's magic number
    upload(page, "#scene-environment", "green.exr", exr, "image/x-exr")
    drawn(page, "box.glb under green.exr")
    green = pixels(page)
    r, g, b = colour_of(green, green[..., 3] > 0)
    assert g > 3 * r and g > 3 * b

    # The fit on screen: silver (on the built-in sphere and room again) is bluer against its red than gold.
    page.click("#scene-default")
    drawn(page, "sphere under room")
    page.select_option("#material", "library:Ag")
    silver = settled(page)
    page.wait_for_function("(id) => document.getElementById('scene').dataset.fit === id", arg=silver)
    drawn(page, "sphere under room")
    ag = pixels(page)
    ag_mask = ag[..., 3] > 0
    r_ag, _, b_ag = colour_of(ag, ag_mask)
    r_au, _, b_au = colour_of(sphere, sphere_mask)
    assert b_ag / r_ag > b_au / r_au + 0.15

    # Bad files: a message, and the scene stays drawn.
    upload(page, "#scene-environment", "broken.hdr", b"not a radiance file at all")
    expect(page.locator("#scene-status")).to_contain_text("broken.hdr is not a readable Radiance .hdr")
    expect(page.locator("#scene-status")).to_have_class("hint error")
    # An OpenEXR file cut inside its header (three's loader alone would never return) and one cut in its pixels.
    upload(page, "#scene-environment", "cut.exr", exr[:100])
    expect(page.locator("#scene-status")).to_contain_text("cut.exr is not a readable OpenEXR .exr: its header ends")
    upload(page, "#scene-environment", "short.exr", exr[: len(exr) - 40])
    expect(page.locator("#scene-status")).to_contain_text("short.exr is not a readable OpenEXR .exr")
    upload(page, "#scene-mesh", "broken.glb", b"glTF\x02\x00\x00\x00garbage")
    expect(page.locator("#scene-status")).to_contain_text("not a readable glTF binary")
    upload(page, "#scene-mesh", "photo.png", b"\x89PNG\r\n")
    expect(page.locator("#scene-status")).to_contain_text("photo.png is not a .glb file")
    assert (pixels(page)[..., 3] > 0).mean() > 0.05

    # Nothing uploaded went to the server, and nothing came from elsewhere.
    host = editor_url.rstrip("/")
    assert all(url.startswith(host) or url.startswith(("blob:", "data:")) for url in requests), requests
    assert not any(url.endswith((".glb", ".hdr", ".exr")) for url in requests)
