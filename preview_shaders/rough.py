"""
Rough preview spheres
=====================

The preview sphere with a GGX lobe: image-based lighting by the
split sum (Karis 2013). The shader ``glsl/preview_rough.frag`` multiplies
the directional albedo from the pre-integrated LUT
(:func:`fitting.shading.ibl.default_lut`, cached on disk) with the
environment prefiltered at the lobe's roughness; this module makes that
prefiltered environment and the spectral reference under the same lighting.

-   :func:`equirect_directions`: the direction of each equirect texel.
-   :func:`environment_equirect`: the preview environment drawn by
    ``cf_environment.glsl`` into an equirect image (render thread).
-   :func:`prefilter_equirect`: the GGX prefilter of an equirect image per
    roughness node, in numpy (Karis 2013's N = V = R assumption: the
    weight of a direction L around R is D(R.h) max(R.L, 0) dOmega).
-   :func:`prefiltered_environment`: the prefiltered slices of a preview
    environment (:data:`ENVIRONMENTS`), computed once per process; the
    editor's WebGL preview gets them from the service.
-   :func:`reference_albedo_table`: the spectral directional albedo over
    cos theta (the same GGX lobe with the exact Fresnel of the measured
    n, k), a 1-D table per eta_i and roughness.
-   :func:`rough_reference_image`: the reference image of a rendered view.

The white sky prefilters to 1 everywhere, so a rough sphere under it shows
the directional albedo itself.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import tempfile
import threading
from pathlib import Path

import numpy as np

from fitting.colour.reference import reference_ACEScg
from fitting.optics.fresnel import fresnel_dielectric
from fitting.shading.ibl import cache_dir, directional_albedo, split_sum_schlick
from fitting.shading.microfacet import alpha_g_from_roughness

from .gl import GLState, check_gl_error, load_shader_source, read_float_target
from .views import ENVIRONMENTS, MODES

__all__ = [
    "MODES",
    "ENVIRONMENTS",
    "EQUIRECT_SIZE",
    "ROUGHNESS_NODES",
    "equirect_directions",
    "environment_equirect",
    "prefilter_equirect",
    "prefiltered_environment",
    "reference_albedo_table",
    "rough_reference_image",
    "render_rough_layers",
]

EQUIRECT_SIZE = (128, 64)
"""(width, height) of the prefiltered equirect slices."""
PREFILTER_VERSION = 1
"""Bumped whenever :func:`prefilter_equirect` changes (part of the cache key)."""
ROUGHNESS_NODES = 9
"""Prefiltered slices at roughness 0, 1/8, ..., 1 (the shader interpolates)."""
_ALBEDO_NODES = 128


def equirect_directions(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """
    Unit directions (height, width, 3) at the texel centres (row 0 up,
    u = 0.5 towards -z, as ``cf_equirect_uv``) and each texel's solid angle.
    """
    phi = ((np.arange(width) + 0.5) / width - 0.5) * 2.0 * np.pi
    theta = (np.arange(height) + 0.5) / height * np.pi
    st = np.sin(theta)[:, None]
    d = np.stack(
        np.broadcast_arrays(st * np.sin(phi)[None, :], np.cos(theta)[:, None], -st * np.cos(phi)[None, :]),
        axis=-1,
    )
    omega = np.broadcast_to((2.0 * np.pi / width) * (np.pi / height) * st, (height, width))
    return d, omega


def _environment_pass(state: GLState, environment_index: int, width: int, height: int):
    ctx = state.ctx
    program, vao = state.program("environment_equirect.frag")
    program["u_environment"].value = int(environment_index)
    program["u_size"].value = (float(width), float(height))
    fbo, targets = state.float_targets((width, height), 1)
    try:
        fbo.use()
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        image = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(height, width, 4)
        check_gl_error(ctx)
    finally:
        state.release_targets(fbo, targets)
    return image[..., :3].copy()


def environment_equirect(thread, environment_index: int, size=EQUIRECT_SIZE) -> np.ndarray:
    """The environment of ``cf_environment.glsl`` as an equirect image (rows from up)."""
    return thread.call(_environment_pass, environment_index, int(size[0]), int(size[1]))


def _downsample(image: np.ndarray) -> np.ndarray:
    """2 x 2 box average of an equirect image (its texel centres stay on the
    same latitude / longitude grid at half the resolution)."""
    h, w, c = image.shape
    return image.reshape(h // 2, 2, w // 2, 2, c).mean(axis=(1, 3))


def prefilter_equirect(image: np.ndarray, nodes: int = ROUGHNESS_NODES) -> np.ndarray:
    """
    GGX-prefiltered copies of an equirect image, (nodes, height, width, 3)
    float32, at roughness j/(nodes - 1): each texel is the normalised sum
    over the texels L of D(R.h) max(R.L, 0) dOmega_L times their radiance,
    h = normalize(R + L) (Karis 2013 with N = V = R). Roughness is clamped
    to ROUGHNESS_MIN as the BRDF does; node 0 is the image itself (at that
    roughness the lobe is narrower than a texel). From roughness 1/2 on
    (lobes wider than ~15 degrees) the sum runs over the image box-averaged
    2 x 2, which changes those slices by far less than their blur. A
    constant image prefilters to itself (the weights are normalised).
    """
    image = np.asarray(image, dtype=np.float64)
    height, width, _ = image.shape
    out = np.empty((nodes, height * width, 3))
    if np.all(image == image.reshape(-1, 3)[0]):
        out[:] = image.reshape(-1, 3)[None]
        return out.reshape(nodes, height, width, 3).astype(np.float32)
    d, _ = equirect_directions(width, height)
    d = d.reshape(-1, 3).astype(np.float32)
    full = (d, image.reshape(-1, 3), equirect_directions(width, height)[1].reshape(-1))
    if height % 2 == 0 and width % 2 == 0:
        dh, oh = equirect_directions(width // 2, height // 2)
        half = (dh.reshape(-1, 3).astype(np.float32), _downsample(image).reshape(-1, 3), oh.reshape(-1))
    else:
        half = full
    out[0] = full[1]
    for j in range(1, nodes):
        r = j / (nodes - 1)
        a2 = np.float32(float(alpha_g_from_roughness(r)) ** 2)
        source, radiance, omega = half if r >= 0.5 else full
        omega = omega.astype(np.float32)
        for start in range(0, d.shape[0], 1024):
            RL = d[start : start + 1024] @ source.T  # cos between R and every L
            # (R.h)^2 = (1 + R.L) / 2 for h = normalize(R + L).
            c2 = np.float32(0.5) * (np.float32(1.0) + RL)
            D = a2 / (np.float32(np.pi) * (c2 * (a2 - np.float32(1.0)) + np.float32(1.0)) ** 2)
            w = (D * np.maximum(RL, np.float32(0.0)) * omega[None, :]).astype(np.float64)
            out[j, start : start + 1024] = (w @ radiance) / w.sum(axis=1, keepdims=True)
    return out.reshape(nodes, height, width, 3).astype(np.float32)


def _cache_path(environment_index: int, size) -> Path:
    """The on-disk cache file of one prefiltered environment: keyed by the
    environment's GLSL source, the sizes and :data:`PREFILTER_VERSION`."""
    source = load_shader_source("environment_equirect.frag").encode()
    key = hashlib.sha256(
        source + f"|{PREFILTER_VERSION}|{environment_index}|{size}|{ROUGHNESS_NODES}".encode()
    ).hexdigest()[:16]
    return cache_dir() / f"prefiltered_env_v{PREFILTER_VERSION}_{environment_index}_{key}.npy"


def _load_or_prefilter(thread, environment_index: int) -> np.ndarray:
    path = _cache_path(environment_index, EQUIRECT_SIZE)
    width, height = EQUIRECT_SIZE
    try:
        data = np.load(path, allow_pickle=False)
        if data.shape == (ROUGHNESS_NODES, height, width, 3) and data.dtype == np.float32 and np.all(np.isfinite(data)):
            return data
    except (OSError, ValueError):
        pass
    data = prefilter_equirect(environment_equirect(thread, environment_index))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
        try:
            with os.fdopen(fd, "wb") as handle:
                np.save(handle, data, allow_pickle=False)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    except OSError:
        pass
    return data


_PREFILTERED: dict[int, np.ndarray] = {}
_PREFILTERED_LOCK = threading.Lock()


def prefiltered_environment(thread, environment_index: int) -> np.ndarray:
    """:func:`prefilter_equirect` of a preview environment (drawn on
    ``thread``), once per process and cached on disk beside the LUT
    (:func:`fitting.shading.ibl.cache_dir`, written atomically)."""
    key = int(environment_index)
    with _PREFILTERED_LOCK:
        if key not in _PREFILTERED:
            _PREFILTERED[key] = _load_or_prefilter(thread, key)
        return _PREFILTERED[key]


def reference_albedo_table(nk, eta_i: float, roughness: float, step_nm: float = 1.0):
    """
    The spectral directional albedo E(mu) of the GGX lobe of ``roughness``
    with the exact Fresnel of ``nk`` seen from ``eta_i``
    (:func:`fitting.colour.reference.reference_ACEScg` at the microfacet's
    v.h, interpolated from 1025 cos theta nodes), at NdotV nodes
    mu_i = (i/127)^2, by :func:`fitting.shading.ibl.directional_albedo`
    (2048 Hammersley points through visible-normal sampling).

    Returns
    -------
    tuple
        (mu nodes (128,), albedo (128, 3)), linear ACEScg.
    """
    mu = (np.arange(_ALBEDO_NODES) / (_ALBEDO_NODES - 1)) ** 2
    cos_nodes = np.linspace(0.0, 1.0, 1025)
    F_nodes = reference_ACEScg(nk, cos_nodes, eta_i, step_nm)

    def fresnel(VdotH):
        return np.stack([np.interp(VdotH, cos_nodes, F_nodes[:, c]) for c in range(3)], axis=-1)

    return mu, directional_albedo(mu, roughness, fresnel)


def _albedo_at(table, cos_theta):
    mu, E = table
    return np.stack([np.interp(cos_theta, mu, E[:, c]) for c in range(3)], axis=-1)


def rough_reference_image(
    nk,
    cos_theta,
    mask,
    radiance,
    coat_radiance,
    eta_i,
    roughness,
    mode="immersed",
    coat_roughness=0.0,
    step_nm: float = 1.0,
):
    """
    The spectral reference of a rough view under the same prefiltered
    lighting: ``immersed``, E_ref(mu) times the radiance prefiltered at
    ``roughness``; ``coated``, the coat's lobe (Schlick's form at the coat's
    F0, as the shader) times the radiance prefiltered at ``coat_roughness``
    plus (1 - F_coat(mu))^2 E_ref(mu_t) times the base's radiance, E_ref
    from :func:`reference_albedo_table`. float32 linear ACEScg.
    """
    image = np.array(radiance[..., :3], dtype=np.float64)
    mu = cos_theta[mask].astype(np.float64)
    table = reference_albedo_table(nk, eta_i, roughness, step_nm)
    if mode == "immersed":
        image[mask] = _albedo_at(table, mu) * image[mask]
        return image.astype(np.float32)
    eta = float(eta_i)
    mu_t = np.sqrt(1.0 - (1.0 - mu * mu) / (eta * eta))
    T = 1.0 - fresnel_dielectric(mu, 1.0, eta)
    base = (T * T)[:, None] * _albedo_at(table, mu_t) * image[mask]
    coat = 0.0
    if eta > 1.0:
        F0c = ((eta - 1.0) / (eta + 1.0)) ** 2
        coat = split_sum_schlick(mu, coat_roughness, np.full(3, F0c)) * coat_radiance[mask][:, :3]
    image[mask] = coat + base
    return image.astype(np.float32)


def render_rough_layers(state: GLState, lut_data, alpha_range, prefiltered, uniforms, size):
    """On the render thread: colour, geometry, base and coat radiance of
    ``preview_rough.frag``, top row first, float32 (size, size, 4) each."""
    ctx = state.ctx
    program, vao = state.program("preview_rough.frag")
    n_alpha, n_r, n_mu, _ = lut_data.shape
    lut = ctx.texture3d((n_mu, n_r, n_alpha), 3, np.ascontiguousarray(lut_data, "f4").tobytes(), dtype="f4")
    lut.filter = (ctx.NEAREST, ctx.NEAREST)
    nodes, height, width, _ = prefiltered.shape
    env = ctx.texture3d((width, height, nodes), 3, np.ascontiguousarray(prefiltered, "f4").tobytes(), dtype="f4")
    env.filter = (ctx.LINEAR, ctx.LINEAR)
    env.repeat_x, env.repeat_y, env.repeat_z = True, False, False
    for name, value in {
        **uniforms,
        "cf_alpha_range": tuple(float(v) for v in alpha_range),
        "cf_lut": 0,
        "u_prefiltered": 1,
    }.items():
        if name in program:
            program[name].value = value
    fbo, targets = state.float_targets((size, size), 4)
    try:
        lut.use(location=0)
        env.use(location=1)
        fbo.use()
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        layers = [read_float_target(fbo, i, size, size)[::-1].copy() for i in range(4)]
        check_gl_error(ctx)
    finally:
        state.release_targets(fbo, targets)
        lut.release()
        env.release()
    return layers
